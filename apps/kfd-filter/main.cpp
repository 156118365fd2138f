// kfd-filter: keyframe extraction + clustering denoise of every 2D scan of a log (rawlog, ROS 1
// bag, CARMEN).
// All logic lives in kfd::RawlogFilter; this file parses arguments and reports.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/config_cli.h"
#include "common/source_cli.h"
#include "kfd/io/rawlog_filter.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/default_stages.h"
#include "kfd/paper/window_helper.h"
#include "kfd/pipeline/format.h"

namespace {

// "1.0 cm (the estimate's floor; the scans' residuals gave 0.4 cm)": the value the evidence
// denoiser used and where it came from.
std::string rangeNoise(const kfd::SensorSummary& sn) {
    const double used = 100.0 * sn.range_noise_m, measured = 100.0 * sn.range_noise_measured_m;
    const double floor = 100.0 * sn.range_noise_floor_m;
    auto cm = [](double v) { return kfd::format("%.1f cm", v); };
    if (sn.range_noise_configured) return cm(used) + " (configured: sigma_m)";
    if (measured <= 0.0) return cm(used) + " (the estimate's floor: too few residuals to measure)";
    // Each scan's estimate is raised to the floor before smoothing over scans: at the floor
    // (as printed) the scans measured less.
    if (cm(used) == cm(floor))
        return cm(used) + " (the estimate's floor; the scans' residuals gave " + cm(measured) + ")";
    if (cm(used) == cm(measured)) return cm(used) + " (from the scans' residuals)";
    return cm(used) + " (from the scans' residuals, each scan's estimate at least the floor " +
           cm(floor) + "; without the floor " + cm(measured) + ")";
}

// The summary's lines on what was read and written, and the sensor.
void printInputAndSensor(const kfd::RawlogFilterOptions& o, const kfd::RawlogFilterSummary& s) {
    std::printf("kfd-filter summary\n");
    const std::string read = s.input_format == kfd::LogFormat::Rawlog
                                 ? s.layout
                                 : std::string(kfd::toString(s.input_format)) + ": " + s.layout;
    std::printf("  input    %s (%s, %s)\n", o.input.c_str(), read.c_str(),
                kfd::plural(s.sensors, "sensor").c_str());
    std::printf("  output   %s (%s)\n", o.output.c_str(), kfd::toString(s.output_format));
    const kfd::SensorSummary& sn = s.sensor;
    if (sn.beams) {
        std::printf("  sensor   %s%s%zu beams over %.1f deg (%.3f deg per beam)", sn.label.c_str(),
                    sn.label.empty() ? "" : ": ", sn.beams, sn.aperture_deg, sn.resolution_deg);
        if (sn.rate_hz > 0.0) std::printf(", %.1f Hz mean", sn.rate_hz);
        if (sn.median_interval_s > 0.0)
            std::printf(" (median interval %.3f s)", sn.median_interval_s);
        std::printf(", %s\n", sn.odometry ? "odometry" : "no odometry (laser only)");
        if (sn.range_noise_m > 0.0)
            std::printf(
                "  derived  range noise %s; resolution and noise set the evidence denoiser's "
                "thresholds\n",
                rangeNoise(sn).c_str());
    }
}

// The lines on the scans and points (kept, dropped, removed), then each listed stage's own
// counters, as the stage declares them.
void printScansAndPoints(const kfd::RawlogFilterSummary& s) {
    const double removed = static_cast<double>(s.points_removed_noise);
    std::printf("  scans    in %zu, kept %zu, dropped %zu (%.1f %%)\n", s.scans_in, s.scans_kept,
                s.scans_dropped, s.droppedPercent());
    std::printf(
        "  points   in %zu; in kept scans removed: %zu not noise (range limits and filter stages, "
        "below), %zu noise (%.2f %%)\n",
        s.points_in, s.points_removed - s.points_removed_noise, s.points_removed_noise,
        s.points_in ? 100.0 * removed / static_cast<double>(s.points_in) : 0.0);
    if (s.points_removed_noise)
        std::printf("  denoise  at most %.2f %% of a kept scan's returns removed\n",
                    100.0 * s.max_removed_noise_share);
    for (const std::string& line : kfd::stageCounterLines(s.stage_totals))
        std::printf("  %s\n", line.c_str());
}

// Why scans were kept or dropped, and the kept scans the denoisers cut most.
void printReasons(const kfd::RawlogFilterSummary& s) {
    for (const std::string& line : kfd::reasonLines(s)) std::printf("  %s\n", line.c_str());
}

// The line on the output's objects (CARMEN lines, bag messages or MRPT objects).
void printObjects(const kfd::RawlogFilterOptions& o, const kfd::RawlogFilterSummary& s) {
    if (s.output_format == kfd::LogFormat::Carmen)
        std::printf(
            "  lines    out %zu (FLASER/RLASER for the kept scans, ODOM), scans dropped %zu\n",
            s.objects_out, s.objects_dropped);
    else if (s.output_format == kfd::LogFormat::Bag || s.output_format == kfd::LogFormat::Rosbag2 ||
             s.output_format == kfd::LogFormat::Mcap) {
        std::printf("  messages in %zu, out %zu, scans dropped %zu; %s written as %s\n",
                    s.objects_in, s.objects_out, s.objects_dropped,
                    kfd::plural(s.points_marked, "removed point").c_str(),
                    kfd::toString(o.bag.removed));
        std::printf(
            "  compress %s%s (--bag-compression none|lz4|bz2|zstd; lz4 or none write fastest)\n",
            s.output_compression.c_str(),
            o.bag.compression == kfd::BagWriterOptions::Compression::AsInput ? ", as the input"
                                                                             : "");
        for (const std::string& t : s.unread_scans)
            std::printf(
                "  not filtered: %s, copied as it is (kfd reads sensor_msgs/LaserScan "
                "only)\n",
                t.c_str());
        if (s.messages_left_out)
            std::printf(
                "  left out %zu ROS 1 messages of types kfd cannot write as ROS 2 (it "
                "converts LaserScan, Odometry and TFMessage)\n",
                s.messages_left_out);
    } else if (s.input_format == kfd::LogFormat::Rawlog)
        std::printf("  objects  in %zu, out %zu, dropped %zu, odometry actions merged %zu\n",
                    s.objects_in, s.objects_out, s.objects_dropped, s.actions_merged);
    else  // the same unit on both sides: MRPT objects, read from lines or messages
        std::printf(
            "  objects  in %zu (read from %s), out %zu, dropped %zu, odometry actions "
            "merged %zu\n",
            s.objects_converted,
            kfd::plural(s.objects_in,
                        s.input_format == kfd::LogFormat::Carmen ? "CARMEN line" : "bag message")
                .c_str(),
            s.objects_out, s.objects_dropped, s.actions_merged);
}

// The lines on what the door and the source skipped or repaired.
void printRepairs(const kfd::RawlogFilterSummary& s) {
    if (s.scans_skipped) {
        std::printf("  skipped  %zu (bad geometry, dropped from the output):", s.scans_skipped);
        for (std::size_t r = 1; r < kfd::kScanSkipReasons; ++r)
            if (s.skipped_by_reason[r])
                std::printf(" %s %zu", kfd::toString(static_cast<kfd::ScanSkipReason>(r)),
                            s.skipped_by_reason[r]);
        std::printf("\n");
    }
    if (s.beams_bad_range || s.odometry_bad || s.stamps_backwards)
        std::printf(
            "  repaired %s with a bad range marked invalid, %s with non-finite odometry, "
            "%s going backwards\n",
            kfd::plural(s.beams_bad_range, "beam").c_str(),
            kfd::plural(s.odometry_bad, "scan").c_str(),
            kfd::plural(s.stamps_backwards, "stamp").c_str());
    if (s.geometry_resets)
        std::printf("  resets   %zu (scan geometry changed)\n", s.geometry_resets);
    if (s.sensors_evicted)
        std::printf(
            "  evicted  %zu sensors' state (more than %zu sensor labels: the least "
            "recently seen forgotten, its held scan finished first)\n",
            s.sensors_evicted, kfd::StreamFilter::kDefaultMaxSensors);
    const kfd::SourceCounters& src = s.source;  // what the bag or CARMEN source repaired
    if (src.lines_unparsable)
        std::printf("  unparsed %s not CARMEN text skipped (%s, the first at line %zu)\n",
                    (kfd::plural(src.lines_unparsable, "line that is", "lines that are")).c_str(),
                    kfd::plural(src.bytes_unparsable, "byte").c_str(), src.first_unparsable_line);
    if (src.scans_bad_angles)
        std::printf(
            "  angles   %s whose angle fields do not match their beam count "
            "(skipped: bad_aperture)\n",
            kfd::plural(src.scans_bad_angles, "LaserScan").c_str());
    if (src.stamps_zero)
        std::printf("  stamps   %s stamped 0 (unset): their bag time used\n",
                    kfd::plural(src.stamps_zero, "message").c_str());
    if (src.scans_without_odometry)
        std::printf(
            "  odometry %s more than 1 s outside the odometry's time span: no odometry for "
            "them\n",
            kfd::plural(src.scans_without_odometry, "scan").c_str());
}

void printSummary(const kfd::RawlogFilterOptions& o, const kfd::RawlogFilterSummary& s) {
    printInputAndSensor(o, s);
    printScansAndPoints(s);
    printReasons(s);
    printObjects(o, s);
    printRepairs(s);
    std::printf("  time     wall %.2f s, filter %.3f s (%.1f us per scan)\n", s.wall_seconds,
                s.filter_seconds, s.scans_in ? 1e6 * s.filter_seconds / s.scans_in : 0.0);
}

// --list-columns: the per-scan CSV's columns and the counters, each stage's as it declares them.
void printColumns() {
    std::printf(
        "The door's columns: index, timestamp, sensor, kept, reason, points_in, removed_noise,\n"
        "points_out, microseconds; then each listed stage's own, in pipeline order; then\n"
        "icp_goodness, odom_x, odom_y, odom_phi, x, y, phi (kfd/io/scan_csv.h).\n");
    for (const kfd::StageInfo& st : kfd::defaultStageRegistry().stages()) {
        if (st.columns.empty() && st.counters.empty()) continue;
        std::printf("\n%s\n", st.name.c_str());
        for (const kfd::StageColumn& c : st.columns)
            std::printf("  column   %-20s %s\n", c.name.c_str(), c.help.c_str());
        for (const kfd::StageCounter& c : st.counters)
            std::printf("  counter  %-24s %s%s\n", c.name.c_str(), c.help.c_str(),
                        c.kept_only ? "" : " (every scan it ran on)");
    }
}

// --list-keys: one key a line, with its two defaults, its range and its meaning (unit).
void printKeys() {
    const auto& keys = kfd::configKeys();
    int w_name = 3, w_default = 7, w_kfd = 5, w_range = 5;
    for (const auto& k : keys) {
        if (k.name == "pipeline") continue;  // its stage lists run over the columns
        w_name = std::max(w_name, static_cast<int>(k.name.size()));
        w_default = std::max(w_default, static_cast<int>(k.default_value.size()));
        w_kfd = std::max(w_kfd, static_cast<int>(k.kfd_value.size()));
        w_range = std::max(w_range, static_cast<int>(k.range.size()));
    }
    std::printf(
        "kfd: kfd's default (share/kfd/default.ini), the value without -c and of a key a\n"
        "configuration file leaves out; stage: the stage's own (Pipeline::Params{}, a C++ "
        "caller's).\nUnits and meanings in the last column.\n");
    auto row = [&](const std::string& name, const std::string& def, const std::string& kfd,
                   const std::string& range, const std::string& help) {
        std::printf("%-*s  %-*s  %-*s  %-*s  %s\n", w_name, name.c_str(), w_default, def.c_str(),
                    w_kfd, kfd.c_str(), w_range, range.c_str(), help.c_str());
    };
    for (const auto& k : keys)
        if (k.name == "pipeline")
            std::printf("\npipeline: %s, of %s\n  stage   %s\n  kfd     %s\n\n", k.help.c_str(),
                        k.range.c_str(), k.default_value.c_str(), k.kfd_value.c_str());
    row("key", "stage", "kfd", "range", "meaning");
    for (const auto& k : keys)
        if (k.name != "pipeline") row(k.name, k.default_value, k.kfd_value, k.range, k.help);
}

void printWindowSuggestion(const std::vector<double>& a) {
    const double pp = a.size() > 2 ? a[2] : 0.985;
    kfd::WindowSuggestion s;
    try {
        s = kfd::suggestWindow(a[0], a[1], pp);
    } catch (const std::exception& e) {
        throw kfd::app::UsageError(std::string("--suggest-window: ") + e.what());
    }
    std::printf("dx = %.3f cm per scan (Formula 4)\n", s.dx_cm);
    if (s.m_min) std::printf("Formula 5 allows m = %zu..%zu\n", s.m_min, s.m_max);
    std::printf("window = %zu\np_pair = %g (P_threshold = %.4f)\n", s.m, pp, s.p_threshold);
    if (!s.note.empty()) std::printf("note: %s\n", s.note.c_str());
}

// kfd-filter's flags beyond RawlogFilterOptions.
struct Flags {
    std::string config;
    bool print_config = false, list_keys = false, list_columns = false, list = false;
    std::vector<double> window;
    std::string compression = "input", removed_as = "nan";
};

void addInputOutputOptions(kfd::app::Cli& cli, kfd::RawlogFilterOptions& opts, Flags& f) {
    cli.option("-i,--input", opts.input,
               "input log: rawlog (either MRPT layout, plain or gzip),\n"
               "ROS 1 bag, ROS 2 bag (a rosbag2 folder, a .db3 or an\n"
               ".mcap), or CARMEN log (.clf/.log, plain or gzip)")
        ->type_name("FILE");
    cli.option("-o,--output", opts.output,
               "output, its format by its name: X.rawlog, X.bag (for a ROS 1\n"
               "bag input), X.db3 or X.mcap (ROS 2, for any bag input), X.clf\n"
               "or X.log (CARMEN; X.clf.gz, X.log.gz: gzip);\n"
               "written to a temporary file, then renamed")
        ->type_name("FILE");
    kfd::app::addSourceOptions(cli, opts.source, f.list, opts.laser_only, " (the output keeps it)");
    cli.option("--removed-as", f.removed_as, "bag output: removed points as nan or inf (REP 117)")
        ->type_name("MARK")
        ->check(CLI::IsMember({"nan", "inf"}))
        ->capture_default_str();
    cli.option("--bag-compression", f.compression,
               "bag output's chunks: input (the input bag's), none, lz4, bz2\n"
               "(ROS 1) or zstd (MCAP); .mcap from another input: zstd")
        ->type_name("C")
        ->check(CLI::IsMember({"input", "none", "lz4", "bz2", "zstd"}))
        ->capture_default_str();
}

void addConfigOptions(kfd::app::Cli& cli, kfd::RawlogFilterOptions& opts, Flags& f) {
    cli.option("-c,--config", f.config,
               ".ini ([KFD] section) or .yaml configuration;\n"
               "default: kfd's defaults (= share/kfd/default.ini, compiled in);\n"
               "the paper's exact method: share/kfd/paper-mit-*.ini")
        ->type_name("FILE");
    cli.option("--stats", opts.stats_csv,
               "per-scan CSV, kfd-icp-slam's scans.csv columns: index, timestamp,\n"
               "sensor, kept, reason, P_common, points and clusters removed,\n"
               "microseconds, view change, degeneracy, corridor, odometry\n"
               "(docs/USAGE.md lists them)")
        ->type_name("FILE");
    cli.option("--compress", opts.compress_level, "gzip level of the output, 0-9")
        ->type_name("N")
        ->check(kfd::app::inRange(0, 9))
        ->capture_default_str();
    cli.addQuiet();
    cli.flag("--print-config", f.print_config, "print the effective configuration and exit");
    cli.flag("--list-keys", f.list_keys,
             "list every configuration key with its defaults, range and\n"
             "meaning, then exit");
    cli.flag("--list-columns", f.list_columns,
             "list the per-scan CSV's columns and the counters each stage\n"
             "declares, with their meaning, then exit");
    cli.option("--suggest-window", f.window,
               "Formulas 4-5: suggest the window m for speed V (m/s) and\n"
               "scan rate F (Hz), then exit",
               2, 3)
        ->option_text("V F [P_PAIR]");
}

// The run: one of the listing and printing flags, or the log filtered and its summary.
void run(kfd::app::Cli& cli, kfd::RawlogFilterOptions& opts, const Flags& f) {
    if (f.list_keys) return printKeys();
    if (f.list_columns) return printColumns();
    if (!f.window.empty()) return printWindowSuggestion(f.window);
    if (f.list) {
        if (opts.input.empty()) throw kfd::app::UsageError("--list: no input log (-i)");
        return kfd::app::printListing(opts.input, opts.source);
    }
    opts.bag.removed = kfd::parseRemovedMark(f.removed_as);
    opts.bag.compression = kfd::parseBagCompression(f.compression);
    opts.pipeline = kfd::app::loadConfig(f.config, "kfd-filter");
    if (f.print_config) {
        std::fputs(kfd::toIni(opts.pipeline).c_str(), stdout);
        return;
    }
    if (opts.input.empty()) throw kfd::app::UsageError("no input log (-i)");
    if (opts.output.empty()) throw kfd::app::UsageError("no output (-o)");
    kfd::app::checkOutputPaths({{"input log", opts.input}, {"configuration", f.config}},
                               {{"output", opts.output}, {"stats file", opts.stats_csv}});
    if (auto* progress = cli.progress())
        opts.on_progress = [progress](const kfd::RawlogProgress& p) {
            progress->update(
                p.bytes_total ? static_cast<double>(p.bytes_read) / p.bytes_total : 0.0, p.scans_in,
                p.scans_kept);
        };
    const auto summary = kfd::RawlogFilter().run(opts);
    printSummary(opts, summary);
}

}  // namespace

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-filter",
        "-i IN.{rawlog,bag,db3,mcap,clf,log[.gz]} -o OUT.{rawlog,bag,db3,mcap,clf,log[.gz]} "
        "[options]",
        "Drops 2D range scans that carry no new information (keyframe extraction, Hu et al. 2023)\n"
        "and removes noise points from the kept scans (clustering denoise). Every other object is\n"
        "copied unchanged and in order; odometry of dropped frames is composed into the next kept\n"
        "action. Removed points are marked invalid (beam count and angles are kept).\n"
        "The input's format is told by its content: an MRPT rawlog, a ROS 1 bag (LaserScan with\n"
        "Odometry or /tf; plain, bz2 or lz4), a ROS 2 bag (a rosbag2 folder or .db3, or an MCAP\n"
        "file) or a CARMEN log (plain or gzip). A bag input can give a bag output (-o X.bag for\n"
        "a ROS 1 bag; -o X.db3 or X.mcap for any bag): every other topic copied in order, the\n"
        "dropped scans left out, removed points written as NaN (or +Inf, --removed-as; REP 117).\n"
        "A ROS 1 bag's LaserScan, Odometry and TFMessage become ROS 2 messages in a .db3 or\n"
        "an .mcap; its other topics are left out (counted). Any input\n"
        "can give a CARMEN log (-o X.clf or X.log, .gz for gzip): FLASER lines for the kept\n"
        "scans (removed points as 0, no reading), ODOM lines for the odometry.",
        "Exit status: 0 on success, 1 on bad input or configuration (an output that is an input\n"
        "included), 2 on bad usage, 130/143 when interrupted (no output is left).");
    kfd::RawlogFilterOptions opts;
    Flags f;
    addInputOutputOptions(cli, opts, f);
    addConfigOptions(cli, opts, f);
    cli.addVersion(KFD_VERSION);
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM/SIGHUP
    return cli.run(argc, argv, [&] { run(cli, opts, f); });
}
