// Progress lines on stderr for the command-line apps: an updating line on a terminal, one line
// per 10 % otherwise (logs stay short).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace kfd::app {

class ProgressPrinter {
  public:
    explicit ProgressPrinter(std::string app)
        : app_(std::move(app)), tty_(isatty(fileno(stderr))) {}

    void update(double fraction, std::size_t scans, std::size_t kept) {
        const int pct = static_cast<int>(100.0 * std::clamp(fraction, 0.0, 1.0));
        if (tty_) {
            std::fprintf(stderr, "\r[%s] %3d%%  %zu scans, %zu kept", app_.c_str(), pct, scans,
                         kept);
            if (pct >= 100) std::fputc('\n', stderr);
        } else if (pct / 10 != last_decile_) {
            last_decile_ = pct / 10;
            std::fprintf(stderr, "[%s] %3d%%  %zu scans, %zu kept\n", app_.c_str(), pct, scans,
                         kept);
        }
    }
    /// Ends an unfinished terminal line before an error message.
    void abort() const {
        if (tty_) std::fputc('\n', stderr);
    }

  private:
    std::string app_;
    bool tty_;
    int last_decile_ = -1;
};

}  // namespace kfd::app
