// The command-line layer of kfd's apps, over CLI11: typed options whose errors name the flag and
// the bad value, generated help, the exit-code contract (0 success, 1 bad input or
// configuration, 2 bad usage, 128 + N when stopped by signal N), the shared progress printer and
// the SIGINT/SIGTERM/SIGHUP handling (a cancellation request the libraries' loops honour, so that
// no temporary or partial output remains).
#pragma once

#include <CLI/CLI.hpp>
#include <charconv>
#include <functional>
#include <optional>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "kfd/os/output_paths.h"
#include "kfd/pipeline/error.h"

namespace kfd::app {

/// Bad usage found after parsing (a missing or contradictory argument): exit status 2.
class UsageError : public kfd::Error {
  public:
    using Error::Error;
};

/// kfd::checkOutputPaths for what only the app knows (a configuration file, several outputs of
/// a library that checks its own): throws kfd::PathError (exit status 1) naming both paths.
void checkOutputPaths(const std::vector<kfd::NamedPath>& inputs,
                      const std::vector<kfd::NamedPath>& outputs);

/// Progress lines on stderr: an updating line on a terminal, one line per 10 % otherwise (logs
/// stay short). "[app]  42%  1200 scans, 310 kept", or "... 1200 scans" for apps that keep every
/// scan (kfd-simulate, kfd-inject).
class ProgressPrinter {
  public:
    explicit ProgressPrinter(std::string app);
    void update(double fraction, std::size_t scans, std::size_t kept);
    /// The scans so far, without a "kept" count.
    void update(double fraction, std::size_t scans);
    /// Ends an unfinished terminal line before an error message.
    void abort();

  private:
    void print(double fraction, const std::string& counts);

    std::string app_;
    bool tty_;
    bool open_line_ = false;
    int last_decile_ = -1;
};

/// Reads `text` as a number of type T into `value`. Returns the message of a text that is not
/// one as a whole, in base 10 ("'abc' is not an integer", "'1e999' is out of range"), or
/// empty. A leading '+' is accepted.
template <class T>
std::string parseNumber(const std::string& text, T& value) {
    static_assert(std::is_arithmetic_v<T>);
    const char* begin = text.data();
    const char* end = begin + text.size();
    if (end - begin > 1 && *begin == '+' && begin[1] != '-') ++begin;
    const auto r = std::from_chars(begin, end, value);
    if (begin != end && r.ec == std::errc() && r.ptr == end) return {};
    const char* kind = std::is_floating_point_v<T> ? "a number"
                       : std::is_signed_v<T>       ? "an integer"
                                                   : "a non-negative integer";
    if (r.ec == std::errc::result_out_of_range && r.ptr == end)
        return "'" + text + "' is out of range";
    return "'" + text + "' is not " + kind;
}

/// parseNumber() that throws UsageError (for option(names, value, help, parse)).
template <class T>
T toNumber(const std::string& text) {
    T value{};
    if (const std::string e = parseNumber(text, value); !e.empty()) throw UsageError(e);
    return value;
}

/// A validator for option(): a number in [lo, hi] ("'12' is outside [0, 9]").
template <class T>
CLI::Validator inRange(T lo, T hi) {
    auto check = [lo, hi](std::string& text) -> std::string {
        T value{};
        if (std::string e = parseNumber(text, value); !e.empty()) return e;
        if (value >= lo && value <= hi) return {};
        return "'" + text + "' is outside [" + CLI::detail::to_string(lo) + ", " +
               CLI::detail::to_string(hi) + "]";
    };
    return CLI::Validator(check, "");
}

/// One app's command line. The app declares its options, then hands its body to run().
class Cli {
  public:
    /// `synopsis` follows "Usage: NAME " in the help; `about` and `footer` frame the generated
    /// list of options.
    Cli(std::string name, const std::string& synopsis, std::string about, std::string footer = {});

    /// The CLI11 app, for what the helpers below do not cover.
    CLI::App& app() { return app_; }

    /// A typed option ("-i,--input"), or a positional argument when `names` has no dash. A
    /// number must parse as a whole, in base 10: "--flag: 'abc' is not a number".
    template <class T>
    CLI::Option* option(const std::string& names, T& value, const std::string& help) {
        if constexpr (std::is_arithmetic_v<T>) {
            return option(names, value, help, toNumber<T>)
                ->type_name(CLI::detail::type_name<T>())
                ->default_function([&value] { return CLI::detail::to_string(value); });
        } else {
            return app_.add_option(names, value, help);
        }
    }
    /// An option of `n_min` to `n_max` numbers (e.g. "--size W H"), given once.
    template <class T>
    CLI::Option* option(const std::string& names, std::vector<T>& values, const std::string& help,
                        int n_min, int n_max) {
        auto set = [&values](const std::vector<std::string>& texts) {
            values.clear();
            for (const auto& t : texts) values.push_back(toNumber<T>(t));
        };
        return app_.add_option_function<std::vector<std::string>>(names, set, help)
            ->expected(n_min, n_max)
            ->check(numberCheck<T>())
            ->multi_option_policy(CLI::MultiOptionPolicy::Throw);
    }
    /// An option whose text `parse` turns into the value; what `parse` throws for a bad text
    /// becomes the usage error "--flag: what".
    template <class T, class Parse>
    CLI::Option* option(const std::string& names, T& value, const std::string& help, Parse parse) {
        auto check = [parse](std::string& text) -> std::string {
            try {
                (void)parse(text);
                return {};
            } catch (const kfd::Error& e) {
                return e.detail();  // the flag is named by the caller, not the library's field
            } catch (const std::exception& e) {
                return e.what();
            }
        };
        return app_
            .add_option_function<std::string>(
                names, [&value, parse](const std::string& text) { value = parse(text); }, help)
            ->check(CLI::Validator(check, ""));
    }
    CLI::Option* flag(const std::string& names, bool& value, const std::string& help) {
        return app_.add_flag(names, value, help);
    }
    /// -q, --quiet: then progress() is null.
    void addQuiet(const std::string& help = "no progress on stderr");
    /// --version prints "NAME VERSION".
    void addVersion(const std::string& version);
    /// A flag that prints `text()` on stdout and exits 0 at once, before required arguments are
    /// checked (like --version), e.g. `kfd-icp-slam --list-modes`.
    void addInfoFlag(const std::string& names, const std::string& help,
                     std::function<std::string()> text);
    /// For apps that write files: while the body runs, SIGINT, SIGTERM and SIGHUP call
    /// kfd::requestCancel() instead of killing the process, so that the library loops stop and
    /// remove their temporary outputs (exit status 128 + N: 130, 143, 129); a second signal
    /// kills at once. A signal ignored when the app starts (nohup) stays ignored. Apps that write
    /// nothing keep the default (killed at once).
    void cancelOnSignal() { cancel_on_signal_ = true; }
    /// The progress printer, or null when -q was given.
    ProgressPrinter* progress();

    /// Parses argv, then runs `body`. Returns the exit status: 0 on success, help or version;
    /// 2 on bad usage from the parser or a UsageError ("NAME: message" and "Try 'NAME --help'."
    /// on stderr); 1 on any other exception ("NAME: what", an MRPT exception's banner and call
    /// stack reduced to its message by kfd::plainMessage), an output that aliases an input
    /// included; 128 + N when signal N (SIGINT, SIGTERM, SIGHUP) stopped the run
    /// (kfd::Cancelled). With cancelOnSignal(), those signals call kfd::requestCancel() while
    /// `body` runs.
    int run(int argc, char** argv, const std::function<void()>& body);

  private:
    template <class T>
    static CLI::Validator numberCheck() {
        return CLI::Validator(
            [](std::string& text) {
                T value{};
                return parseNumber(text, value);
            },
            "");
    }
    std::string unexpected(int argc, char** argv) const;
    int usageError(const std::string& message) const;

    std::string name_;
    CLI::App app_;
    bool quiet_ = false;
    bool cancel_on_signal_ = false;
    std::optional<ProgressPrinter> progress_;
};

}  // namespace kfd::app
