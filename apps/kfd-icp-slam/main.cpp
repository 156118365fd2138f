// kfd-icp-slam: MRPT ICP-SLAM over a log (rawlog, ROS 1 or ROS 2 bag, CARMEN) with the kfd
// pre-filter in front. All logic lives in kfd::IcpSlamRunner; this file parses arguments and
// reports.
#include <cstdio>
#include <string>

#include "common/cli.h"
#include "common/ground_truth_cli.h"
#include "common/source_cli.h"
#include "kfd/pipeline/format.h"
#include "kfd/report/slam_report.h"
#include "kfd/slam/icp_slam_runner.h"

namespace {

// What the command line sets.
struct Args {
    kfd::IcpSlamOptions o;
    std::string rawlog_arg;  // LOG, the positional form of -i
    bool list = false;       // --list
    bool no_map = false;
    kfd::app::GroundTruthArgs gt;
};

// --list-modes: "name<TAB>stages<TAB>description", one line a mode, for scripts.
std::string listModes() {
    std::string text;
    for (const auto& m : kfd::prefilterModes()) {
        std::string stages;
        for (const auto& st : m.stages) stages += (stages.empty() ? "" : ",") + st;
        if (m.uses_kfd_stages) stages = "[KFD] pipeline (default " + stages + ")";
        text += m.name + "\t" + (stages.empty() ? "-" : stages) + "\t" + m.description + "\n";
    }
    return text;
}

// The configuration, the log and how it is read, the output folder.
void addInputOptions(kfd::app::Cli& cli, Args& a) {
    cli.option("CONFIG.ini", a.o.config_file, "ICP-SLAM configuration (and optional [KFD])")
        ->type_name("FILE");
    cli.option("LOG", a.rawlog_arg,
               "input log: rawlog, ROS 1 bag, ROS 2 bag (rosbag2 folder, .db3,\n"
               ".mcap) or CARMEN log (or -i)")
        ->type_name("FILE");
    cli.option("-i,--rawlog", a.o.rawlog, "input log (default: [MappingApplication] rawlog_file)")
        ->type_name("FILE");
    kfd::app::addSourceOptions(cli, a.o.source, a.list, a.o.laser_only,
                               "; nor does ICP-SLAM get any (what a robot\nwithout wheel "
                               "odometry sees)");
    cli.option("-o,--out", a.o.output_dir,
               "output folder (default: [MappingApplication] "
               "logOutput_dir)")
        ->type_name("DIR");
}

// The pre-filter's mode, the matched drop rates, the skipped start.
void addModeOptions(kfd::app::Cli& cli, Args& a) {
    cli.option("-m,--mode", a.o.mode, "pre-filter mode (default kfd; see --list-modes)",
               kfd::parsePrefilterMode)
        ->type_name("MODE");
    cli.addInfoFlag("--list-modes", "list every mode with its stages and exit", listModes);
    cli.option("--match-drop", a.o.odometry_target_drop_pct,
               "odometry or decimate mode: drop PCT % of the scans (odometry:\n"
               "the motion thresholds that do; decimate: keep 1 - PCT/100)",
               kfd::app::toNumber<double>)
        ->type_name("PCT");
    cli.option("--match-drop-of", a.o.match_drop_of,
               "odometry or decimate mode: drop as many scans as MODE does\n"
               "on this log with these options (a pre-pass of the pre-filter)",
               kfd::parsePrefilterMode)
        ->type_name("MODE");
    cli.option("--skip-scans", a.o.skip_scans,
               "skip the first K scans of the log (repeats that start later)")
        ->type_name("K");
    cli.option("--split-seconds", a.o.split_seconds,
               "relations over at most S s are local, the others long")
        ->type_name("S")
        ->capture_default_str();
}

// The evaluation (relations, ground truth, the local/long split) and the maps.
void addEvaluationOptions(kfd::app::Cli& cli, Args& a) {
    kfd::app::addGroundTruthOptions(cli, a.gt, "relations file only: report the relations error",
                                    "ground-truth TUM trajectory only: ATE RMSE, drawn in\n"
                                    "the figure");
    cli.option("--max-dt", a.o.relations_max_dt, "stamp matching tolerance (s)")
        ->type_name("S")
        ->capture_default_str();
    cli.flag("--no-map", a.no_map,
             "skip the maps: final_map.simplemap, map.png, map_figure.png,\nreport.md, "
             "_finalmap_.simplemap, _finalmaps_.txt_*");
}

// The run: the log's listing (--list), or ICP-SLAM, its report and its summary.
void run(kfd::app::Cli& cli, Args& a) {
    if (!a.rawlog_arg.empty()) {
        if (!a.o.rawlog.empty()) throw kfd::app::UsageError("input log given twice");
        a.o.rawlog = a.rawlog_arg;
    }
    if (a.list) {  // `kfd-icp-slam --list LOG` (no configuration needed)
        const std::string log = !a.o.rawlog.empty() ? a.o.rawlog : a.o.config_file;
        if (log.empty()) throw kfd::app::UsageError("--list: no input log");
        return kfd::app::printListing(log, a.o.source);
    }
    if (a.o.config_file.empty()) throw kfd::app::UsageError("no configuration (CONFIG.ini)");
    kfd::app::resolveGroundTruth(a.gt, a.o.relations, a.o.ground_truth_tum);
    if (a.no_map) a.o.write_map = false;
    if (auto* progress = cli.progress())
        a.o.on_progress = [progress](const kfd::IcpSlamProgress& p) {
            progress->update(p.fraction, p.scans_in, p.scans_kept);
        };
    const auto result = [&] {
        try {
            return kfd::IcpSlamRunner().run(a.o);
        } catch (const kfd::SlamOptionError& e) {  // options that contradict: usage
            throw kfd::app::UsageError(e.what());
        }
    }();
    kfd::writeIcpSlamReport(result);
    for (const auto& notice : result.summary.notices)  // a key or map kfd did not honour
        std::fprintf(stderr, "kfd-icp-slam: warning: %s\n", notice.c_str());
    std::fputs(kfd::summaryText(result.summary).c_str(), stdout);  // as report.md
}

}  // namespace

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-icp-slam", "CONFIG.ini [LOG] [options]",
        "Runs MRPT's ICP-SLAM (CMetricMapBuilderICP) like icp-slam does, reading the same .ini\n"
        "([ICP], [MappingApplication], map definitions), with a pre-filter in front of scan\n"
        "matching configured by an optional [KFD] section (see kfd-filter --list-keys).\n"
        "LOG is an MRPT rawlog, a ROS 1 or ROS 2 bag (LaserScan with Odometry or /tf; a rosbag2\n"
        "folder, a .db3 or an .mcap) or a CARMEN log.",
        "Writes trajectory.tum (a pose for every input scan), scans.csv, summary.json,\n"
        "final_map.simplemap, map.png, map_figure.png and report.md into the output folder, and\n"
        "icp-slam's files as [MappingApplication] asks: log_estimated_path.txt,\n"
        "log_odometry_path.txt, log_times.txt, log_MemoryUsage.txt, _finalmap_.simplemap,\n"
        "_finalmaps_.txt_*; every LOG_FREQUENCY steps mapbuild_posepdf_NNN.txt (SAVE_POSE_LOG)\n"
        "and buildingmap_NNNNN.3Dscene (SAVE_3D_SCENE, for SceneViewer3D). A key it ignores\n"
        "(SHOW_PROGRESS_3D_REAL_TIME: no window) is a warning on stderr. The folder is staged in\n"
        "a temporary folder and moved in at the end; its other files are kept.\n"
        "Exit status: 0 on success, 1 on bad input or configuration (an output that is an input\n"
        "included), 2 on bad usage, 130/143 when interrupted (no output is left).");
    Args a;
    addInputOptions(cli, a);
    addModeOptions(cli, a);
    addEvaluationOptions(cli, a);
    cli.addQuiet();
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM/SIGHUP
    return cli.run(argc, argv, [&] { run(cli, a); });
}
