// kfd-icp-slam: MRPT ICP-SLAM over a log (rawlog, ROS 1 bag, CARMEN) with the kfd pre-filter in
// front.
// All logic lives in kfd::IcpSlamRunner; this file parses arguments and reports.
#include <cstdio>
#include <string>
#include <utility>

#include "common/cli.h"
#include "common/ground_truth_cli.h"
#include "common/source_cli.h"
#include "kfd/report/slam_report.h"
#include "kfd/slam/icp_slam_runner.h"

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-icp-slam", "CONFIG.ini [LOG] [options]",
        "Runs MRPT's ICP-SLAM (CMetricMapBuilderICP) like icp-slam does, reading the same .ini\n"
        "([ICP], [MappingApplication], map definitions), with a pre-filter in front of scan\n"
        "matching configured by an optional [KFD] section (see kfd-filter --list-keys).\n"
        "LOG is an MRPT rawlog, a ROS 1 bag (LaserScan with Odometry or /tf) or a CARMEN log.",
        "Writes trajectory.tum (a pose for every input scan), log_estimated_path.txt (icp-slam's\n"
        "format), scans.csv, summary.json, final_map.simplemap, map.png, map_figure.png and\n"
        "report.md into the output folder (staged in a temporary folder and moved in at the end;\n"
        "the folder's other files are kept).\n"
        "Exit status: 0 on success, 1 on bad input or configuration (an output that is an input\n"
        "included), 2 on bad usage, 130/143 when interrupted (no output is left).");
    kfd::IcpSlamOptions o;
    std::string rawlog_arg;
    bool list = false;
    cli.option("CONFIG.ini", o.config_file, "ICP-SLAM configuration (and optional [KFD])")
        ->type_name("FILE");
    cli.option("LOG", rawlog_arg, "input log: rawlog, ROS 1 bag or CARMEN log (or -i)")
        ->type_name("FILE");
    cli.option("-i,--rawlog", o.rawlog, "input log (default: [MappingApplication] rawlog_file)")
        ->type_name("FILE");
    kfd::app::addSourceOptions(cli, o.source, list, o.laser_only,
                               "; nor does ICP-SLAM get any (what a robot\nwithout wheel "
                               "odometry sees)");
    cli.option("-o,--out", o.output_dir,
               "output folder (default: [MappingApplication] "
               "logOutput_dir)")
        ->type_name("DIR");
    cli.option("-m,--mode", o.mode, "pre-filter mode (default kfd; see --list-modes)",
               kfd::parsePrefilterMode)
        ->type_name("MODE");
    cli.addInfoFlag("--list-modes", "list every mode with its stages and exit", [] {
        std::string text;  // "name<TAB>stages<TAB>description": one line a mode, for scripts
        for (const auto& m : kfd::prefilterModes()) {
            std::string stages;
            for (const auto& st : m.stages) stages += (stages.empty() ? "" : ",") + st;
            if (m.uses_kfd_stages) stages = "[KFD] pipeline (default " + stages + ")";
            text += m.name + "\t" + (stages.empty() ? "-" : stages) + "\t" + m.description + "\n";
        }
        return text;
    });
    cli.option("--match-drop", o.odometry_target_drop_pct,
               "odometry or decimate mode: drop PCT % of the scans (odometry:\n"
               "the motion thresholds that do; decimate: keep 1 - PCT/100)",
               kfd::app::toNumber<double>)
        ->type_name("PCT");
    cli.option("--match-drop-of", o.match_drop_of,
               "odometry or decimate mode: drop as many scans as MODE does\n"
               "on this log with these options (a pre-pass of the pre-filter)",
               kfd::parsePrefilterMode)
        ->type_name("MODE");
    cli.option("--skip-scans", o.skip_scans,
               "skip the first K scans of the log (repeats that start later)")
        ->type_name("K");
    cli.option("--split-seconds", o.split_seconds,
               "relations over at most S s are local, the others long")
        ->type_name("S")
        ->capture_default_str();
    kfd::app::GroundTruthArgs gt_args;
    kfd::app::addGroundTruthOptions(cli, gt_args, "relations file only: report the relations error",
                                    "ground-truth TUM trajectory only: ATE RMSE, drawn in\n"
                                    "the figure");
    cli.option("--max-dt", o.relations_max_dt, "stamp matching tolerance (s)")
        ->type_name("S")
        ->capture_default_str();
    bool no_map = false;
    cli.flag("--no-map", no_map, "skip final_map.simplemap and map.png");
    cli.addQuiet();
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM/SIGHUP
    return cli.run(argc, argv, [&] {
        if (!rawlog_arg.empty()) {
            if (!o.rawlog.empty()) throw kfd::app::UsageError("input log given twice");
            o.rawlog = rawlog_arg;
        }
        if (list) {  // `kfd-icp-slam --list LOG` (no configuration needed)
            const std::string log = !o.rawlog.empty() ? o.rawlog : o.config_file;
            if (log.empty()) throw kfd::app::UsageError("--list: no input log");
            return kfd::app::printListing(log, o.source);
        }
        if (o.config_file.empty()) throw kfd::app::UsageError("no configuration (CONFIG.ini)");
        kfd::app::resolveGroundTruth(gt_args, o.relations, o.ground_truth_tum);
        if (no_map) o.write_map = false;
        if (auto* progress = cli.progress())
            o.on_progress = [progress](const kfd::IcpSlamProgress& p) {
                progress->update(p.fraction, p.scans_in, p.scans_kept);
            };
        const auto result = [&] {
            try {
                return kfd::IcpSlamRunner().run(o);
            } catch (const kfd::SlamOptionError& e) {  // options that contradict: usage
                throw kfd::app::UsageError(e.what());
            }
        }();
        kfd::writeIcpSlamReport(result);
        const auto& s = result.summary;
        std::printf("kfd-icp-slam summary (mode %s)\n", kfd::toString(s.mode));
        std::printf("  input      %s\n  output     %s\n", s.rawlog.c_str(), s.output_dir.c_str());
        std::printf("  scans      in %zu, kept %zu, dropped %.1f %%\n", s.scans_in, s.scans_kept,
                    s.dropped_pct);
        std::printf("  points     removed %zu of %zu\n", s.points_removed, s.points_in);
        std::printf(
            "  time       pre-filter %.1f us/scan, ICP-SLAM %.3f ms/scan, CPU %.2f s, "
            "wall %.2f s\n",
            s.prefilter_us_per_scan, s.icp_ms_per_scan, s.cpu_s_total, s.wall_s_total);
        if (s.icp_runs)
            std::printf("  ICP        %zu corrections, %zu rejected, median goodness %.2f\n",
                        s.icp_runs, s.icp_rejected, s.icp_goodness_median);
        if (s.rematches)
            std::printf(
                "  re-match   %zu after a rejection (%zu by the gap check, %zu then "
                "accepted), %zu dropped scans matched again\n",
                s.rematches, s.gap_checks_failed, s.rematches_recovered, s.scans_rematched);
        if (!s.lost_track_stamps.empty())
            std::printf(
                "  WARNING    %zu suspected lost track%s (%zu ICP corrections rejected in a row), "
                "first at t = %.3f s: see report.md and scans.csv's icp_goodness\n",
                s.lost_track_stamps.size(), s.lost_track_stamps.size() == 1 ? "" : "s",
                kfd::kLostTrackRejections, s.lost_track_stamps.front());
        if (s.ate_rmse) std::printf("  ATE        RMSE %.4f m\n", *s.ate_rmse);
        if (s.relations) {
            const auto& r = *s.relations;
            std::printf(
                "  relations  %zu used, %zu unmatched: trans %.4f +- %.4f m, rot %.3f +- "
                "%.3f deg\n",
                r.used, r.unmatched, r.trans_mean, r.trans_std, r.rot_mean_deg, r.rot_std_deg);
            for (const auto& [name, sub] :
                 {std::pair{"local", &s.relations_local}, std::pair{"long ", &s.relations_long}})
                if (*sub)
                    std::printf("    %s    (%s %g s) %zu used: trans %.4f +- %.4f m\n", name,
                                sub == &s.relations_local ? "<=" : ">", s.split_seconds,
                                (*sub)->used, (*sub)->trans_mean, (*sub)->trans_std);
        }
        if (s.target_drop_pct)
            std::printf("  matched    drop target %.2f %%\n", *s.target_drop_pct);
    });
}
