#include "common/cli.h"

#include <unistd.h>

#include <csignal>

#include <algorithm>
#include <cstdio>
#include <memory>

#include "kfd/os/cancel.h"
#include "kfd/pipeline/format.h"

namespace kfd::app {

ProgressPrinter::ProgressPrinter(std::string app)
    : app_(std::move(app)), tty_(isatty(fileno(stderr))) {}

void ProgressPrinter::update(double fraction, std::size_t scans, std::size_t kept) {
    print(fraction, kfd::plural(scans, "scan") + ", " + std::to_string(kept) + " kept");
}

void ProgressPrinter::update(double fraction, std::size_t scans) {
    print(fraction, kfd::plural(scans, "scan"));
}

void ProgressPrinter::print(double fraction, const std::string& counts) {
    const int pct = static_cast<int>(100.0 * std::clamp(fraction, 0.0, 1.0));
    if (tty_) {
        std::fprintf(stderr, "\r[%s] %3d%%  %s", app_.c_str(), pct, counts.c_str());
        open_line_ = pct < 100;
        if (!open_line_) std::fputc('\n', stderr);
    } else if (pct / 10 != last_decile_) {
        last_decile_ = pct / 10;
        std::fprintf(stderr, "[%s] %3d%%  %s\n", app_.c_str(), pct, counts.c_str());
    }
}

void ProgressPrinter::abort() {
    if (open_line_) std::fputc('\n', stderr);
    open_line_ = false;
}

namespace {

/// CLI11's help with the app's own synopsis first: usage, about, options, footer.
class HelpFormatter : public CLI::Formatter {
  public:
    explicit HelpFormatter(std::string usage) : usage_(std::move(usage)) { column_width(28); }
    std::string make_help(const CLI::App* app, std::string,
                          CLI::AppFormatMode mode) const override {
        std::string out = usage_ + "\n";
        if (!app->get_description().empty()) out += "\n" + app->get_description() + "\n";
        out += make_positionals(app) + make_groups(app, mode) + "\n" + make_footer(app);
        return out;
    }

  private:
    std::string usage_;
};

}  // namespace

Cli::Cli(std::string name, const std::string& synopsis, std::string about, std::string footer)
    : name_(std::move(name)), app_(std::move(about), name_) {
    app_.formatter(std::make_shared<HelpFormatter>("Usage: " + name_ + " " + synopsis));
    app_.footer(std::move(footer));
    app_.set_help_flag("-h,--help", "this text");
    // Like the hand-written parsers before: a repeated option keeps its last value.
    app_.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
}

void Cli::addQuiet(const std::string& help) { flag("-q,--quiet", quiet_, help); }

void Cli::addVersion(const std::string& version) {
    app_.set_version_flag("--version", name_ + " " + version, "version");
}

void Cli::addInfoFlag(const std::string& names, const std::string& help,
                      std::function<std::string()> text) {
    app_.add_flag_callback(
        names,
        [text = std::move(text)] {
            std::fputs(text().c_str(), stdout);
            throw CLI::Success();
        },
        help);
}

ProgressPrinter* Cli::progress() {
    if (quiet_) return nullptr;
    if (!progress_) progress_.emplace(name_);
    return &*progress_;
}

std::string Cli::unexpected(int argc, char** argv) const {
    // CLI11's message, with the arguments in command-line order (2.1 prints them reversed).
    std::vector<std::string> left = app_.remaining(), ordered;
    for (int i = 1; i < argc; ++i) {
        const auto it = std::find(left.begin(), left.end(), argv[i]);
        if (it == left.end()) continue;
        ordered.push_back(*it);
        left.erase(it);
    }
    ordered.insert(ordered.end(), left.begin(), left.end());
    return (ordered.size() > 1 ? "The following arguments were not expected: "
                               : "The following argument was not expected: ") +
           CLI::detail::join(ordered, " ");
}

int Cli::usageError(const std::string& message) const {
    std::fprintf(stderr, "%s: %s\nTry '%s --help'.\n", name_.c_str(), message.c_str(),
                 name_.c_str());
    return 2;
}

namespace {

// SIGINT / SIGTERM / SIGHUP (the terminal closed, an ssh session dropped): ask the running
// library loop to stop (it unwinds and its temporary outputs are removed); SA_RESETHAND makes a
// second signal end the process at once.
extern "C" void onSignal(int sig) { kfd::requestCancel(sig); }

void installSignalHandlers() {
    struct sigaction sa {};
    sa.sa_handler = onSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
        struct sigaction old {};
        // A signal the caller ignores (nohup, `trap '' HUP`) stays ignored.
        if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        sigaction(sig, &sa, nullptr);
    }
}

}  // namespace

void checkOutputPaths(const std::vector<kfd::NamedPath>& inputs,
                      const std::vector<kfd::NamedPath>& outputs) {
    kfd::checkOutputPaths(inputs, outputs);
}

int Cli::run(int argc, char** argv, const std::function<void()>& body) {
    try {
        app_.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::fputs(app_.help().c_str(), stdout);
        return 0;
    } catch (const CLI::CallForVersion& e) {
        std::printf("%s\n", e.what());
        return 0;
    } catch (const CLI::Success&) {  // an info flag printed its text
        return 0;
    } catch (const CLI::ExtrasError&) {
        return usageError(unexpected(argc, argv));
    } catch (const CLI::RequiredError& e) {
        // An unknown argument explains a missing one ("--ouput x"): name it first.
        return usageError(app_.remaining().empty() ? e.what() : unexpected(argc, argv));
    } catch (const CLI::ParseError& e) {
        return usageError(e.what());
    }
    if (cancel_on_signal_) installSignalHandlers();
    try {
        body();  // a signal after the outputs were moved into place changes nothing
        return 0;
    } catch (const kfd::Cancelled& e) {
        if (progress_) progress_->abort();
        std::fprintf(stderr, "%s: %s\n", name_.c_str(), e.what());
        return 128 + e.signal();
    } catch (const UsageError& e) {
        if (progress_) progress_->abort();
        return usageError(e.what());
    } catch (const std::exception& e) {  // kfd::Error and anything else the libraries throw
        if (progress_) progress_->abort();
        // An MRPT exception that got this far: its message, not its banner and call stack.
        std::fprintf(stderr, "%s: %s\n", name_.c_str(), kfd::plainMessage(e.what()).c_str());
        return 1;
    }
}

}  // namespace kfd::app
