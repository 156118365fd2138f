// kfd-filter: keyframe extraction + clustering denoise of every 2D scan of a rawlog.
// All logic lives in kfd::RawlogFilter; this file parses arguments and reports.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "common/progress.h"
#include "kfd/core/window_helper.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/rawlog_filter.h"

namespace {

const char* kUsage =
    "Usage: kfd-filter -i IN.rawlog -o OUT.rawlog [options]\n"
    "\n"
    "Drops 2D range scans that carry no new information (keyframe extraction, Hu et al. 2023)\n"
    "and removes noise points from the kept scans (clustering denoise). Every other object is\n"
    "copied unchanged and in order; odometry of dropped frames is composed into the next kept\n"
    "action. Removed points are marked invalid (beam count and angles are kept).\n"
    "\n"
    "Options:\n"
    "  -i, --input FILE        input rawlog (either MRPT layout, plain or gzip)\n"
    "  -o, --output FILE       output rawlog (written to a temporary file, then renamed)\n"
    "  -c, --config FILE       .ini ([KFD] section) or .yaml configuration;\n"
    "                          default: built-in defaults (= share/kfd/paper-mit-0.752.ini)\n"
    "      --stats FILE        per-scan CSV (timestamp, sensor, keyframe, reason, P_common,\n"
    "                          clusters, points removed, microseconds)\n"
    "      --compress N        gzip level of the output, 0-9 (default 1)\n"
    "  -q, --quiet             no progress on stderr\n"
    "      --print-config      print the effective configuration and exit\n"
    "      --list-keys         list every configuration key with its range and exit\n"
    "      --suggest-window V F [P_PAIR]\n"
    "                          Formulas 4-5: suggest the window m for speed V (m/s) and scan\n"
    "                          rate F (Hz), then exit\n"
    "  -h, --help              this text\n"
    "      --version           version\n"
    "\n"
    "Exit status: 0 on success, 1 on bad input or configuration, 2 on bad usage.\n";

int usageError(const std::string& msg) {
    std::fprintf(stderr, "kfd-filter: %s\nTry 'kfd-filter --help'.\n", msg.c_str());
    return 2;
}

void printSummary(const kfd::RawlogFilterOptions& o, const kfd::RawlogFilterSummary& s) {
    const double removed = static_cast<double>(s.points_removed_noise);
    std::printf("kfd-filter summary\n");
    std::printf("  input    %s (%s, %zu sensor%s)\n", o.input.c_str(), s.layout.c_str(), s.sensors,
                s.sensors == 1 ? "" : "s");
    std::printf("  output   %s\n", o.output.c_str());
    std::printf("  scans    in %zu, kept %zu, dropped %zu (%.1f %%)\n", s.scans_in, s.scans_kept,
                s.scans_dropped, s.droppedPercent());
    std::printf("  points   in %zu; in kept scans removed: %zu out of range, %zu noise (%.2f %%)\n",
                s.points_in, s.points_removed_range, s.points_removed_noise,
                s.points_in ? 100.0 * removed / static_cast<double>(s.points_in) : 0.0);
    std::printf("  objects  in %zu, out %zu, dropped %zu, odometry actions merged %zu\n",
                s.objects_in, s.objects_out, s.objects_dropped, s.actions_merged);
    if (s.geometry_resets)
        std::printf("  resets   %zu (scan geometry changed)\n", s.geometry_resets);
    std::printf("  time     wall %.2f s, filter %.3f s (%.1f us per scan)\n", s.wall_seconds,
                s.filter_seconds, s.scans_in ? 1e6 * s.filter_seconds / s.scans_in : 0.0);
}

}  // namespace

int main(int argc, char** argv) {
    kfd::RawlogFilterOptions opts;
    std::string config;
    bool quiet = false, print_config = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&](const char* name) -> const char* {
            if (i + 1 >= argc) return nullptr;
            (void)name;
            return argv[++i];
        };
        if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (a == "--version") {
            std::printf("kfd-filter %s\n", KFD_VERSION);
            return 0;
        } else if (a == "-i" || a == "--input") {
            const char* v = value("input");
            if (!v) return usageError(a + " needs a file name");
            opts.input = v;
        } else if (a == "-o" || a == "--output") {
            const char* v = value("output");
            if (!v) return usageError(a + " needs a file name");
            opts.output = v;
        } else if (a == "-c" || a == "--config") {
            const char* v = value("config");
            if (!v) return usageError(a + " needs a file name");
            config = v;
        } else if (a == "--stats") {
            const char* v = value("stats");
            if (!v) return usageError(a + " needs a file name");
            opts.stats_csv = v;
        } else if (a == "--compress") {
            const char* v = value("compress");
            char* end = nullptr;
            const long lvl = v ? std::strtol(v, &end, 10) : -1;
            if (!v || *end || lvl < 0 || lvl > 9) return usageError("--compress needs 0-9");
            opts.compress_level = static_cast<int>(lvl);
        } else if (a == "-q" || a == "--quiet") {
            quiet = true;
        } else if (a == "--print-config") {
            print_config = true;
        } else if (a == "--list-keys") {
            for (const auto& k : kfd::configKeys())
                std::printf("%-22s %-28s %s\n", k.name.c_str(), k.range.c_str(), k.help.c_str());
            return 0;
        } else if (a == "--suggest-window") {
            if (i + 2 >= argc) return usageError("--suggest-window needs SPEED RATE [P_PAIR]");
            try {
                const double v = std::stod(argv[++i]);
                const double f = std::stod(argv[++i]);
                double pp = 0.985;
                if (i + 1 < argc && argv[i + 1][0] != '-') pp = std::stod(argv[++i]);
                const auto s = kfd::suggestWindow(v, f, pp);
                std::printf("dx = %.3f cm per scan (Formula 4)\n", s.dx_cm);
                if (s.m_min) std::printf("Formula 5 allows m = %zu..%zu\n", s.m_min, s.m_max);
                std::printf("window = %zu\np_pair = %g (P_threshold = %.4f)\n", s.m, pp,
                            s.p_threshold);
                if (!s.note.empty()) std::printf("note: %s\n", s.note.c_str());
                return 0;
            } catch (const std::exception& e) {
                return usageError(std::string("--suggest-window: ") + e.what());
            }
        } else {
            return usageError("unknown argument '" + a + "'");
        }
    }

    try {
        if (!config.empty()) opts.pipeline = kfd::loadConfigFile(config);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd-filter: %s\n", e.what());
        return 1;
    }
    if (print_config) {
        std::fputs(kfd::toIni(opts.pipeline).c_str(), stdout);
        return 0;
    }
    if (opts.input.empty()) return usageError("no input rawlog (-i)");
    if (opts.output.empty()) return usageError("no output rawlog (-o)");

    kfd::app::ProgressPrinter progress("kfd-filter");
    if (!quiet) {
        opts.on_progress = [&](const kfd::RawlogProgress& p) {
            progress.update(p.bytes_total ? static_cast<double>(p.bytes_read) / p.bytes_total : 0.0,
                            p.scans_in, p.scans_kept);
        };
    }
    try {
        const auto summary = kfd::RawlogFilter().run(opts);
        printSummary(opts, summary);
    } catch (const std::exception& e) {
        if (!quiet) progress.abort();
        std::fprintf(stderr, "kfd-filter: %s\n", e.what());
        return 1;
    }
    return 0;
}
