#include "kfd/slam/icp_slam_runner.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDF.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/slam/CMetricMapBuilderICP.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>

#include "kfd/baselines/motion_stage.h"
#include "kfd/eval/ate.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/render/map_figure.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;
using mrpt::obs::CObservation2DRangeScan;
constexpr const char* kSect = "MappingApplication";

double stampOf(const mrpt::obs::CObservation& o) {
    return o.timestamp == mrpt::Clock::time_point() ? 0.0 : mrpt::Clock::toDouble(o.timestamp);
}

// Odometry of a scan stream, from either rawlog layout, for the motion-based stages.
struct OdometryTracker {
    mrpt::poses::CPose2D accum;
    std::optional<Pose2D> current;
    void onAction(const mrpt::obs::CActionCollection& a) {
        if (auto mv = a.getBestMovementEstimation()) {
            accum = accum + mv->rawOdometryIncrementReading;
            current = Pose2D{accum.x(), accum.y(), accum.phi()};
        }
    }
    void onObservation(const mrpt::obs::CObservation& o) {
        if (const auto* odo = dynamic_cast<const mrpt::obs::CObservationOdometry*>(&o))
            current = Pose2D{odo->odometry.x(), odo->odometry.y(), odo->odometry.phi()};
    }
};

struct ScanStamp {
    double t;
    std::optional<Pose2D> odometry;
};

// Reads only timestamps and odometry of every scan (for matching the odometry baseline's drop
// rate to a target before the real run).
std::vector<ScanStamp> scanOdometry(const std::string& rawlog) {
    mrpt::io::CFileGZInputStream in(rawlog);
    auto arch = mrpt::serialization::archiveFrom(in);
    std::vector<ScanStamp> out;
    OdometryTracker odo;
    mrpt::obs::CActionCollection::Ptr action;
    mrpt::obs::CSensoryFrame::Ptr sf;
    mrpt::obs::CObservation::Ptr obs;
    std::size_t entry = 0;
    while (
        mrpt::obs::CRawlog::getActionObservationPairOrObservation(arch, action, sf, obs, entry)) {
        if (obs) {
            odo.onObservation(*obs);
            if (IS_CLASS(*obs, CObservation2DRangeScan))
                out.push_back({stampOf(*obs), odo.current});
        } else if (sf) {
            if (action) odo.onAction(*action);
            for (const auto& o : *sf)
                if (IS_CLASS(*o, CObservation2DRangeScan))
                    out.push_back({stampOf(*o), odo.current});
        }
    }
    return out;
}

double dropPct(const std::vector<ScanStamp>& scans, const MotionFilter::Params& p) {
    MotionFilter f(p);
    std::size_t dropped = 0;
    for (const auto& s : scans) dropped += f.keep(s.t, s.odometry) ? 0 : 1;
    return scans.empty() ? 0.0 : 100.0 * static_cast<double>(dropped) / scans.size();
}

// Bisection on D (angle = 30 deg per metre of D): the drop rate grows with D.
MotionFilter::Params matchDropRate(const std::vector<ScanStamp>& scans, double target_pct) {
    MotionFilter::Params p;
    p.max_interval_s = 0.0;
    double lo = 0.0, hi = 5.0;
    for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        p.max_distance_m = mid;
        p.max_angle_deg = 30.0 * mid;
        if (dropPct(scans, p) < target_pct)
            lo = mid;
        else
            hi = mid;
    }
    p.max_distance_m = hi;
    p.max_angle_deg = 30.0 * hi;
    return p;
}

}  // namespace

IcpSlamSummary IcpSlamRunner::run(const IcpSlamOptions& opts) {
    const auto wall0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    IcpSlamSummary sum;
    sum.mode = opts.mode;

    std::error_code ec;
    if (!fs::is_regular_file(opts.config_file, ec))
        throw SlamError("configuration file not found: " + opts.config_file);
    mrpt::config::CConfigFile cfg(opts.config_file);
    sum.rawlog = !opts.rawlog.empty() ? opts.rawlog : cfg.read_string(kSect, "rawlog_file", "");
    sum.output_dir =
        !opts.output_dir.empty() ? opts.output_dir : cfg.read_string(kSect, "logOutput_dir", "");
    if (sum.rawlog.empty()) throw SlamError("no rawlog given (option or rawlog_file)");
    if (!fs::is_regular_file(sum.rawlog, ec)) throw SlamError("rawlog not found: " + sum.rawlog);
    if (sum.output_dir.empty()) throw SlamError("no output folder given (option or logOutput_dir)");

    // Pre-filter configuration: [KFD] when present, else the built-in defaults.
    Pipeline::Params kfd_params;
    if (cfg.sectionExists("KFD")) kfd_params = loadIni(cfg, "KFD");
    sum.pipeline = pipelineForMode(opts.mode, kfd_params);
    if (opts.mode == PrefilterMode::Odometry && opts.odometry_target_drop_pct) {
        const double target = *opts.odometry_target_drop_pct;
        if (!(target >= 0.0 && target < 100.0))
            throw SlamError("the target drop rate must be in [0, 100)");
        try {
            sum.pipeline.get<MotionStage>() = matchDropRate(scanOdometry(sum.rawlog), target);
        } catch (const std::exception& e) {
            throw SlamError(std::string("cannot read the rawlog: ") + e.what());
        }
    }
    StreamFilter prefilter(sum.pipeline);

    std::vector<Relation> relations;
    if (!opts.relations.empty()) relations = readRelations(opts.relations);  // EvalError

    // The map builder, configured exactly as icp-slam does.
    mrpt::slam::CMetricMapBuilderICP builder;
    builder.setVerbosityLevel(mrpt::system::LVL_ERROR);
    builder.ICP_options.loadFromConfigFile(cfg, kSect);
    builder.ICP_params.loadFromConfigFile(cfg, "ICP");
    builder.initialize();
    builder.options.alwaysInsertByClass.fromString(
        cfg.read_string(kSect, "alwaysInsertByClass", ""));
    const std::size_t rawlog_offset =
        static_cast<std::size_t>(std::max(0, cfg.read_int(kSect, "rawlog_offset", 0)));

    fs::create_directories(sum.output_dir, ec);
    if (ec) throw SlamError("cannot create the output folder " + sum.output_dir);
    const fs::path out(sum.output_dir);
    std::ofstream f_path(out / "log_estimated_path.txt"), f_csv(out / "scans.csv");
    if (!f_path || !f_csv) throw SlamError("cannot write into " + sum.output_dir);
    f_csv << "index,timestamp,sensor,kept,reason,p_common,points_in,points_removed,prefilter_us,"
             "x,y,phi\n";

    mrpt::io::CFileGZInputStream in;
    if (!in.open(sum.rawlog)) throw SlamError("cannot open the rawlog " + sum.rawlog);
    const double total_bytes =
        static_cast<double>(std::max<std::uintmax_t>(1, fs::file_size(sum.rawlog, ec)));
    auto arch = mrpt::serialization::archiveFrom(in);

    Trajectory traj, odo_traj;
    std::vector<std::size_t> keyframes;
    OdometryTracker odo;
    double prefilter_us = 0.0, builder_s = 0.0;
    std::size_t entry = 0, step = 0;
    char buf[256];
    struct Pending {
        double t;
        std::string sensor;
        StreamResult r;
    };
    std::vector<Pending> entry_scans;

    auto prefilterScan = [&](CObservation2DRangeScan& scan) {
        StreamResult r = prefilter.process(scan, odo.current);
        ++sum.scans_in;
        sum.scans_kept += r.keep;
        sum.points_in += r.report.points_in;
        if (r.keep) sum.points_removed += r.report.points_in - r.report.points_out;
        prefilter_us += r.report.microseconds;
        entry_scans.push_back({stampOf(scan), scan.sensorLabel, std::move(r)});
        return entry_scans.back().r.keep;
    };

    for (;;) {
        mrpt::obs::CActionCollection::Ptr action;
        mrpt::obs::CSensoryFrame::Ptr sf;
        mrpt::obs::CObservation::Ptr obs;
        try {
            if (!mrpt::obs::CRawlog::getActionObservationPairOrObservation(arch, action, sf, obs,
                                                                           entry))
                break;
        } catch (const std::exception& e) {
            throw SlamError("cannot read rawlog entry " + std::to_string(entry) + " of " +
                            sum.rawlog + " (truncated or not a rawlog?)");
        }
        if (entry < rawlog_offset) continue;
        entry_scans.clear();
        if (obs) {
            odo.onObservation(*obs);
            bool process = true;
            if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(obs))
                process = prefilterScan(*scan);
            if (process) {
                const auto t0 = std::chrono::steady_clock::now();
                builder.processObservation(obs);
                builder_s +=
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            }
        } else if (sf && action) {
            odo.onAction(*action);
            for (auto it = sf->begin(); it != sf->end();) {
                auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(*it);
                if (scan && !prefilterScan(*scan))
                    it = sf->erase(it);
                else
                    ++it;
            }
            const auto t0 = std::chrono::steady_clock::now();
            builder.processActionObservation(*action, *sf);  // odometry kept even if sf is empty
            builder_s +=
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        } else {
            continue;
        }
        const auto pose = builder.getCurrentPoseEstimation()->getMeanVal();
        std::snprintf(buf, sizeof(buf), "%i %f %f %f\n", static_cast<int>(step), pose.x(), pose.y(),
                      pose.yaw());
        f_path << buf;
        for (const auto& s : entry_scans) {
            if (s.r.keep) keyframes.push_back(traj.size());
            if (odo.current) odo_traj.push_back(StampedPose{s.t, *odo.current});
            traj.push_back(StampedPose{s.t, Pose2D{pose.x(), pose.y(), pose.yaw()}});
            const auto& rep = s.r.report;
            const auto* kf = rep.find<KeyframeDecision>();
            std::snprintf(buf, sizeof(buf), "%zu,%.6f,%s,%d,%s,%.6f,%zu,%zu,%.2f,%.6f,%.6f,%.6f\n",
                          traj.size() - 1, s.t, s.sensor.c_str(), s.r.keep ? 1 : 0,
                          kf ? toString(kf->reason) : (s.r.keep ? "kept" : rep.dropped_by.c_str()),
                          kf ? kf->p_common : 0.0, rep.points_in, rep.points_in - rep.points_out,
                          rep.microseconds, pose.x(), pose.y(), pose.yaw());
            f_csv << buf;
        }
        ++step;
        ++sum.entries;
        if (opts.on_progress && step % 500 == 0)
            opts.on_progress({sum.entries, sum.scans_in, sum.scans_kept,
                              static_cast<double>(in.getPosition()) / total_bytes});
    }
    if (sum.entries == 0) throw SlamError("no entries in " + sum.rawlog + ": not a rawlog?");
    if (opts.on_progress) opts.on_progress({sum.entries, sum.scans_in, sum.scans_kept, 1.0});
    f_path.close();
    f_csv.close();
    writeTum((out / "trajectory.tum").string(), traj);

    Trajectory gt;
    if (!opts.ground_truth_tum.empty()) {
        gt = readTum(opts.ground_truth_tum);  // EvalError
        sortByTime(gt);
        Trajectory sorted = traj;
        sortByTime(sorted);
        sum.ate_rmse = computeAte(sorted, gt, opts.relations_max_dt).rmse;
    }
    if (opts.write_map) {
        builder.saveCurrentMapToFile((out / "final_map.simplemap").string());
        mrpt::maps::CSimpleMap sm;
        builder.getCurrentlyBuiltMap(sm);
        mrpt::maps::COccupancyGridMap2D grid(-10, 10, -10, 10, 0.05f);
        grid.loadFromSimpleMap(sm);
        grid.saveAsBitmapFile((out / "map.png").string());
        MapFigureInput fig;
        fig.grid = &grid;
        fig.estimate = traj;
        fig.ground_truth = gt;
        fig.odometry = odo_traj;
        fig.keyframes = keyframes;
        fig.title = fs::path(sum.rawlog).filename().string() + "  mode " + toString(opts.mode);
        renderMapFigure(fig).saveToFile((out / "map_figure.png").string());
    }

    sum.dropped_pct = sum.scans_in ? 100.0 * static_cast<double>(sum.scans_in - sum.scans_kept) /
                                         static_cast<double>(sum.scans_in)
                                   : 0.0;
    sum.prefilter_us_per_scan = sum.scans_in ? prefilter_us / static_cast<double>(sum.scans_in) : 0;
    sum.icp_ms_per_scan = sum.scans_in ? 1e3 * builder_s / static_cast<double>(sum.scans_in) : 0;
    sum.icp_ms_per_kept_scan =
        sum.scans_kept ? 1e3 * builder_s / static_cast<double>(sum.scans_kept) : 0;
    if (!relations.empty()) {
        Trajectory sorted = traj;
        sortByTime(sorted);
        sum.relations = evaluateRelations(sorted, relations, opts.relations_max_dt);
        sum.relations_file = opts.relations;
    }
    sum.cpu_s_total = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    sum.wall_s_total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    std::ofstream((out / "summary.json").string()) << toJson(sum);
    if (opts.write_map) {  // a human-readable report tying the figure to the numbers
        std::ofstream r((out / "report.md").string());
        char line[512];
        r << "# kfd-icp-slam report\n\n";
        r << "- rawlog: `" << sum.rawlog << "`\n- pre-filter mode: **" << toString(sum.mode)
          << "**\n";
        std::snprintf(line, sizeof(line),
                      "- scans: %zu in, %zu kept (%.1f %% dropped); points removed: %zu of %zu\n"
                      "- time: pre-filter %.1f us/scan, ICP-SLAM %.3f ms/scan, CPU %.2f s\n",
                      sum.scans_in, sum.scans_kept, sum.dropped_pct, sum.points_removed,
                      sum.points_in, sum.prefilter_us_per_scan, sum.icp_ms_per_scan,
                      sum.cpu_s_total);
        r << line;
        if (sum.relations) {
            std::snprintf(line, sizeof(line),
                          "- relations error (%zu used, %zu unmatched): %.4f +- %.4f m, %.3f +- "
                          "%.3f deg\n",
                          sum.relations->used, sum.relations->unmatched, sum.relations->trans_mean,
                          sum.relations->trans_std, sum.relations->rot_mean_deg,
                          sum.relations->rot_std_deg);
            r << line;
        }
        if (sum.ate_rmse) r << "- ATE RMSE after SE(2) alignment: " << *sum.ate_rmse << " m\n";
        r << "\n![map, estimate (blue, dots = keyframes), ground truth (green), odometry (grey)]"
             "(map_figure.png)\n\nAll numbers: `summary.json`; per scan: `scans.csv`; "
             "trajectory: `trajectory.tum`.\n";
    }
    return sum;
}

std::string toJson(const IcpSlamSummary& s) {
    auto esc = [](const std::string& v) {
        std::string o;
        for (char c : v) {
            if (c == '"' || c == '\\') o += '\\';
            o += c;
        }
        return o;
    };
    char buf[4096];
    std::string stages;
    for (const auto& st : s.pipeline.stages) stages += (stages.empty() ? "\"" : ", \"") + st + "\"";
    std::snprintf(buf, sizeof(buf),
                  "{\n  \"mode\": \"%s\",\n  \"rawlog\": \"%s\",\n  \"stages\": [%s],\n"
                  "  \"entries\": %zu,\n  \"scans_in\": %zu,\n  \"scans_kept\": %zu,\n"
                  "  \"dropped_pct\": %.3f,\n  \"points_in\": %zu,\n  \"points_removed\": %zu,\n"
                  "  \"prefilter_us_per_scan\": %.3f,\n  \"icp_ms_per_scan\": %.4f,\n"
                  "  \"icp_ms_per_kept_scan\": %.4f,\n  \"cpu_s_total\": %.3f,\n"
                  "  \"wall_s_total\": %.3f,\n  \"motion_distance_m\": %.6f,\n"
                  "  \"motion_angle_deg\": %.6f",
                  toString(s.mode), esc(s.rawlog).c_str(), stages.c_str(), s.entries, s.scans_in,
                  s.scans_kept, s.dropped_pct, s.points_in, s.points_removed,
                  s.prefilter_us_per_scan, s.icp_ms_per_scan, s.icp_ms_per_kept_scan, s.cpu_s_total,
                  s.wall_s_total, s.pipeline.get<MotionStage>().max_distance_m,
                  s.pipeline.get<MotionStage>().max_angle_deg);
    std::string j = buf;
    if (s.ate_rmse) {
        std::snprintf(buf, sizeof(buf), ",\n  \"ate_rmse_m\": %.6f", *s.ate_rmse);
        j += buf;
    }
    if (s.relations) {
        const auto& r = *s.relations;
        std::snprintf(buf, sizeof(buf),
                      ",\n  \"relations\": {\n    \"file\": \"%s\",\n    \"used\": %zu,\n"
                      "    \"unmatched\": %zu,\n    \"trans_mean_m\": %.6f,\n"
                      "    \"trans_std_m\": %.6f,\n    \"rot_mean_deg\": %.6f,\n"
                      "    \"rot_std_deg\": %.6f,\n    \"trans2_mean_m2\": %.6f,\n"
                      "    \"trans2_std_m2\": %.6f,\n    \"rot2_mean_deg2\": %.6f,\n"
                      "    \"rot2_std_deg2\": %.6f\n  }",
                      esc(s.relations_file).c_str(), r.used, r.unmatched, r.trans_mean, r.trans_std,
                      r.rot_mean_deg, r.rot_std_deg, r.trans2_mean, r.trans2_std, r.rot2_mean,
                      r.rot2_std);
        j += buf;
    }
    return j + "\n}\n";
}

}  // namespace kfd
