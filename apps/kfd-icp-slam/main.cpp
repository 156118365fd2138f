// kfd-icp-slam: MRPT ICP-SLAM over a rawlog with the kfd pre-filter in front.
// All logic lives in kfd::IcpSlamRunner; this file parses arguments and reports.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "common/progress.h"
#include "kfd/report/slam_report.h"
#include "kfd/slam/icp_slam_runner.h"

namespace {

const char* kUsage =
    "Usage: kfd-icp-slam CONFIG.ini [RAWLOG] [options]\n"
    "\n"
    "Runs MRPT's ICP-SLAM (CMetricMapBuilderICP) like icp-slam does, reading the same .ini\n"
    "([ICP], [MappingApplication], map definitions), with a pre-filter in front of scan\n"
    "matching configured by an optional [KFD] section (see kfd-filter --list-keys).\n"
    "\n"
    "Options:\n"
    "  -i, --rawlog FILE       input rawlog (default: [MappingApplication] rawlog_file)\n"
    "  -o, --out DIR           output folder (default: [MappingApplication] logOutput_dir)\n"
    "  -m, --mode MODE         none | odometry | keyframe | kfd | dbscan | radius | sor\n"
    "                          (default kfd); dbscan, radius and sor run the distance stage\n"
    "                          and that baseline denoiser on every scan\n"
    "      --match-drop PCT    odometry mode: pick the motion thresholds that drop PCT %% of\n"
    "                          the scans (e.g. kfd's drop rate on the same log)\n"
    "  -g, --relations FILE    ground-truth .relations: report the relations error\n"
    "      --gt FILE           ground-truth trajectory (TUM): ATE RMSE, drawn in the figure\n"
    "      --max-dt S          stamp matching tolerance (default 0.001)\n"
    "      --no-map            skip final_map.simplemap and map.png\n"
    "  -q, --quiet             no progress on stderr\n"
    "  -h, --help              this text\n"
    "\n"
    "Writes trajectory.tum (a pose for every input scan), log_estimated_path.txt (icp-slam's\n"
    "format), scans.csv, summary.json, final_map.simplemap, map.png, map_figure.png and\n"
    "report.md into the output folder.\n"
    "Exit status: 0 on success, 1 on bad input or configuration, 2 on bad usage.\n";

int usageError(const std::string& msg) {
    std::fprintf(stderr, "kfd-icp-slam: %s\nTry 'kfd-icp-slam --help'.\n", msg.c_str());
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    kfd::IcpSlamOptions o;
    bool quiet = false;
    std::vector<std::string> positional;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
        if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (a == "-i" || a == "--rawlog" || a == "-o" || a == "--out" || a == "-m" ||
                   a == "--mode" || a == "-g" || a == "--relations" || a == "--max-dt" ||
                   a == "--match-drop" || a == "--gt") {
            const char* v = next();
            if (!v) return usageError(a + " needs a value");
            try {
                if (a == "-i" || a == "--rawlog")
                    o.rawlog = v;
                else if (a == "-o" || a == "--out")
                    o.output_dir = v;
                else if (a == "-m" || a == "--mode")
                    o.mode = kfd::parsePrefilterMode(v);
                else if (a == "-g" || a == "--relations")
                    o.relations = v;
                else if (a == "--max-dt")
                    o.relations_max_dt = std::stod(v);
                else if (a == "--gt")
                    o.ground_truth_tum = v;
                else
                    o.odometry_target_drop_pct = std::stod(v);
            } catch (const std::exception& e) {
                return usageError(a + ": " + e.what());
            }
        } else if (a == "--no-map") {
            o.write_map = false;
        } else if (a == "-q" || a == "--quiet") {
            quiet = true;
        } else if (!a.empty() && a[0] == '-') {
            return usageError("unknown option '" + a + "'");
        } else {
            positional.push_back(a);
        }
    }
    if (positional.empty()) return usageError("no configuration file");
    if (positional.size() > 2) return usageError("too many arguments");
    o.config_file = positional[0];
    if (positional.size() == 2) {
        if (!o.rawlog.empty()) return usageError("rawlog given twice");
        o.rawlog = positional[1];
    }
    if (o.odometry_target_drop_pct && o.mode != kfd::PrefilterMode::Odometry)
        return usageError("--match-drop applies to --mode odometry only");

    kfd::app::ProgressPrinter progress("kfd-icp-slam");
    if (!quiet) {
        o.on_progress = [&](const kfd::IcpSlamProgress& p) {
            progress.update(p.fraction, p.scans_in, p.scans_kept);
        };
    }
    try {
        const auto result = kfd::IcpSlamRunner().run(o);
        kfd::writeIcpSlamReport(result);
        const auto& s = result.summary;
        std::printf("kfd-icp-slam summary (mode %s)\n", kfd::toString(s.mode));
        std::printf("  rawlog     %s\n  output     %s\n", s.rawlog.c_str(), s.output_dir.c_str());
        std::printf("  scans      in %zu, kept %zu, dropped %.1f %%\n", s.scans_in, s.scans_kept,
                    s.dropped_pct);
        std::printf("  points     removed %zu of %zu\n", s.points_removed, s.points_in);
        std::printf(
            "  time       pre-filter %.1f us/scan, ICP-SLAM %.3f ms/scan, CPU %.2f s, "
            "wall %.2f s\n",
            s.prefilter_us_per_scan, s.icp_ms_per_scan, s.cpu_s_total, s.wall_s_total);
        if (s.ate_rmse) std::printf("  ATE        RMSE %.4f m\n", *s.ate_rmse);
        if (s.relations) {
            const auto& r = *s.relations;
            std::printf(
                "  relations  %zu used, %zu unmatched: trans %.4f +- %.4f m, rot %.3f +- "
                "%.3f deg\n",
                r.used, r.unmatched, r.trans_mean, r.trans_std, r.rot_mean_deg, r.rot_std_deg);
        }
    } catch (const std::exception& e) {
        if (!quiet) progress.abort();
        std::fprintf(stderr, "kfd-icp-slam: %s\n", e.what());
        return 1;
    }
    return 0;
}
