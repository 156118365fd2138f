#include "kfd/slam/icp_slam_runner.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDF.h>
#include <mrpt/slam/CMetricMapBuilderICP.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>

#include "kfd/baselines/decimate_stage.h"
#include "kfd/baselines/motion_stage.h"
#include "kfd/core/cancel.h"
#include "kfd/eval/ate.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/open_source.h"
#include "kfd/mrpt/scan_check.h"
#include "kfd/mrpt/source.h"
#include "kfd/mrpt/stream_filter.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;
using mrpt::obs::CObservation2DRangeScan;
constexpr const char* kSect = "MappingApplication";

// One step of MRPT's icp-slam: an observation on its own, or an odometry action with a sensory
// frame.
struct IcpSlamStep {
    mrpt::obs::CObservation::Ptr observation;
    mrpt::obs::CActionCollection::Ptr action;
    mrpt::obs::CSensoryFrame::Ptr frame;
};

// MRPT's icp-slam reads the log with CRawlog::getActionObservationPairOrObservation: an
// observation on its own is one step; an action is paired with the next sensory frame, and
// whatever lies between them (even another action or observation) is skipped, as is a frame
// without an action. This reproduces that grouping over a source's entries.
class IcpSlamSteps {
  public:
    /// True when `e` completes a step, written to `step`.
    bool feed(const SourceEntry& e, IcpSlamStep& step) {
        using Kind = SourceEntry::Kind;
        step = IcpSlamStep();
        if (pending_) {  // an action waiting for its frame
            if (e.kind != Kind::Frame) return false;
            step.action = std::move(pending_);
            step.frame = e.frame;
            return true;
        }
        if (e.kind == Kind::Observation) {
            step.observation = e.observation;
            return true;
        }
        if (e.kind == Kind::Frame && e.action) {
            step.action = e.action;
            step.frame = e.frame;
            return true;
        }
        if (e.kind == Kind::Action) pending_ = e.action;
        return false;
    }

  private:
    mrpt::obs::CActionCollection::Ptr pending_;
};

std::unique_ptr<Source> openLog(const std::string& path, const SourceOptions& options) {
    try {
        return openSource(path, options);
    } catch (const SourceError& e) {
        throw SlamError(e.what(), path);
    }
}

bool nextEntry(Source& source, SourceEntry& e) {
    try {
        return source.next(e);
    } catch (const SourceError& err) {
        throw SlamError(err.what(), source.path());
    }
}

void checkReadable(const std::string& role, const std::string& path) {
    if (path.empty()) return;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw SlamError(role + " not found: " + path, path);
    if (!std::ifstream(path, std::ios::binary))
        throw SlamError("cannot read the " + role + " " + path, path);
}

struct ScanStamp {
    double t;
    std::optional<Pose2D> odometry;
};

// The 2D scans of one step.
std::size_t scanCount(const IcpSlamStep& step) {
    if (step.observation) return IS_CLASS(*step.observation, CObservation2DRangeScan) ? 1 : 0;
    std::size_t n = 0;
    for (const auto& o : *step.frame) n += IS_CLASS(*o, CObservation2DRangeScan) ? 1 : 0;
    return n;
}

// IcpSlamOptions::skip_scans: true for every step until the first K scans have gone by.
class StartSkipper {
  public:
    explicit StartSkipper(std::size_t k) : left_(k) {}
    bool skip(const IcpSlamStep& step) {
        if (left_ == 0) return false;
        const std::size_t n = scanCount(step);
        skipped_ += n;
        left_ -= std::min(left_, n);
        return true;
    }
    std::size_t skipped() const { return skipped_; }

  private:
    std::size_t left_, skipped_ = 0;
};

// Every 2D scan of the log as the real run meets it (icp-slam's steps, after the skipped
// start), with its entry's odometry: what the pre-passes that match a drop rate read.
template <class Fn>
void forEachRunScan(const std::string& rawlog, const SourceOptions& options, std::size_t skip_scans,
                    Fn&& fn) {
    auto source = openLog(rawlog, options);
    IcpSlamSteps steps;
    IcpSlamStep step;
    StartSkipper skipper(skip_scans);
    SourceEntry e;
    while (nextEntry(*source, e)) {
        throwIfCancelled();
        if (!steps.feed(e, step) || skipper.skip(step)) continue;
        auto visit = [&](mrpt::obs::CObservation& o) {
            if (auto* scan = dynamic_cast<CObservation2DRangeScan*>(&o)) fn(*scan, e.odometry);
        };
        if (step.observation)
            visit(*step.observation);
        else
            for (const auto& o : *step.frame) visit(*o);
    }
}

// Timestamps and odometry of every scan after the skipped start (for matching the odometry
// baseline's drop rate to a target before the real run).
std::vector<ScanStamp> scanOdometry(const std::string& rawlog, const SourceOptions& options,
                                    std::size_t skip_scans, bool laser_only) {
    std::vector<ScanStamp> out;
    forEachRunScan(rawlog, options, skip_scans,
                   [&](const CObservation2DRangeScan& scan, std::optional<Pose2D> odo) {
                       // non-finite: unknown, as checkScan does
                       if (laser_only || (odo && !finitePose(odo->x, odo->y, odo->phi)))
                           odo.reset();
                       out.push_back({stampOf(scan), odo});
                   });
    return out;
}

// The drop rate (%) of a pre-filter over the log, as the real run would see it (the same
// skipped start, the same checks, odometry or none): the pre-filter alone, no ICP.
double pipelineDropPct(const std::string& rawlog, const SourceOptions& options,
                       const Pipeline::Params& pipeline, std::size_t skip_scans, bool laser_only) {
    StreamFilter filter(pipeline);
    std::size_t in = 0, kept = 0;
    forEachRunScan(rawlog, options, skip_scans,
                   [&](CObservation2DRangeScan& scan, std::optional<Pose2D> odo) {
                       if (laser_only) odo.reset();
                       ++in;
                       if (!checkScan(scan, &odo).ok()) return;
                       kept += filter.process(scan, odo).keep ? 1 : 0;
                   });
    return in ? 100.0 * static_cast<double>(in - kept) / static_cast<double>(in) : 0.0;
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

IcpSlamResult IcpSlamRunner::run(const IcpSlamOptions& opts) {
    const auto wall0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    IcpSlamResult res;
    IcpSlamSummary& sum = res.summary;
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
    // Every input readable before the run starts, and no output file is (or aliases) one.
    checkReadable("rawlog", sum.rawlog);
    checkReadable("relations file", opts.relations);
    checkReadable("ground-truth trajectory", opts.ground_truth_tum);
    {
        const std::vector<NamedPath> inputs = {{"configuration", opts.config_file},
                                               {"rawlog", sum.rawlog},
                                               {"relations file", opts.relations},
                                               {"ground-truth trajectory", opts.ground_truth_tum}};
        std::vector<NamedPath> outputs;
        for (const char* name : kIcpSlamOutputFiles)
            outputs.push_back(
                {std::string("output ") + name, (fs::path(sum.output_dir) / name).string()});
        checkOutputPaths(inputs, outputs);
        for (const NamedPath& in : inputs)
            if (samePath(sum.output_dir, in.path))
                throw PathError(
                    "the output folder " + sum.output_dir + " is the " + in.role + " " + in.path,
                    sum.output_dir);
    }

    // Pre-filter configuration: [KFD] when present, else kfd's defaults (share/kfd/default.ini).
    Pipeline::Params kfd_params = kfdDefaults();
    if (cfg.sectionExists("KFD")) kfd_params = loadIni(cfg, "KFD");
    sum.pipeline = pipelineForMode(opts.mode, kfd_params);
    sum.laser_only = opts.laser_only;
    if (!(opts.split_seconds >= 0.0) || !std::isfinite(opts.split_seconds))
        throw SlamError("the local/long split must be finite and >= 0 s (got " +
                            std::to_string(opts.split_seconds) + ")",
                        "split_seconds");
    sum.split_seconds = opts.split_seconds;
    const bool matchable =
        opts.mode == PrefilterMode::Odometry || opts.mode == PrefilterMode::Decimate;
    if ((opts.odometry_target_drop_pct || opts.match_drop_of) && !matchable)
        throw SlamError(
            std::string("a matched drop rate needs the odometry or decimate mode (not ") +
                toString(opts.mode) + ")",
            "mode");
    if (opts.odometry_target_drop_pct && opts.match_drop_of)
        throw SlamError("give a drop rate or a mode to match, not both", "match_drop_of");
    if (opts.match_drop_of) {
        const std::clock_t m0 = std::clock();
        sum.target_drop_pct = pipelineDropPct(sum.rawlog, opts.source,
                                              pipelineForMode(*opts.match_drop_of, kfd_params),
                                              opts.skip_scans, opts.laser_only);
        sum.cpu_s_match = static_cast<double>(std::clock() - m0) / CLOCKS_PER_SEC;
    } else if (opts.odometry_target_drop_pct) {
        sum.target_drop_pct = *opts.odometry_target_drop_pct;
    }
    if (sum.target_drop_pct) {
        const double target = *sum.target_drop_pct;
        if (!(target >= 0.0 && target < 100.0))
            throw SlamError("the target drop rate must be in [0, 100)");
        if (opts.mode == PrefilterMode::Odometry)
            sum.pipeline.get<MotionStage>() = matchDropRate(
                scanOdometry(sum.rawlog, opts.source, opts.skip_scans, opts.laser_only), target);
        else
            sum.pipeline.get<DecimateStage>().keep_fraction = 1.0 - target / 100.0;
    }
    StreamFilter prefilter(sum.pipeline);

    if (!(opts.relations_max_dt >= 0.0) || !std::isfinite(opts.relations_max_dt))
        throw SlamError("the stamp matching tolerance must be finite and >= 0 (got " +
                            std::to_string(opts.relations_max_dt) + " s)",
                        "relations_max_dt");
    std::vector<Relation> relations;
    if (!opts.relations.empty()) {
        relations = readRelations(opts.relations);  // EvalError
        if (relations.empty()) throw SlamError("no relation in " + opts.relations, opts.relations);
    }
    if (!opts.ground_truth_tum.empty()) {  // read before the run: a bad file fails at once
        res.ground_truth = readTum(opts.ground_truth_tum);  // EvalError
        sortByTime(res.ground_truth);
    }

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

    // Everything is written into a staging folder; writeIcpSlamReport() (or
    // result.output->commit()) moves it into place, and on failure it is removed.
    res.output = std::make_shared<StagedOutputFolder>(sum.output_dir);
    const fs::path out = res.output->path();
    std::ofstream f_path(out / "log_estimated_path.txt"), f_csv(out / "scans.csv");
    if (!f_path || !f_csv) throw SlamError("cannot write into " + sum.output_dir);
    f_csv << "index,timestamp,sensor,kept,reason,p_common,points_in,points_removed,prefilter_us,"
             "x,y,phi,view_change,degeneracy,corridor\n";

    auto source = openLog(sum.rawlog, opts.source);
    const double total_bytes =
        static_cast<double>(std::max<std::uint64_t>(1, source->bytesTotal()));

    Trajectory& traj = res.trajectory;
    double prefilter_us = 0.0, builder_s = 0.0;
    std::size_t step_no = 0;
    char buf[256];
    struct Pending {
        double t;
        std::string sensor;
        StreamResult r;
        std::optional<Pose2D> odometry;                 // after kfd::checkScan
        ScanSkipReason skipped = ScanSkipReason::None;  // not None: never reached ICP
    };
    std::vector<Pending> entry_scans;
    SourceEntry e;
    IcpSlamSteps steps;
    IcpSlamStep step;

    // Every scan is checked first, in every mode (`none` included): a bad geometry skips it (it
    // never reaches a stage nor the map builder), bad ranges are marked invalid, non-finite
    // odometry becomes unknown.
    auto prefilterScan = [&](CObservation2DRangeScan& scan) {
        std::optional<Pose2D> odo = opts.laser_only ? std::nullopt : e.odometry;
        const ScanCheck check = checkScan(scan, &odo);
        sum.beams_bad_range += check.bad_ranges;
        sum.odometry_bad += check.bad_odometry ? 1 : 0;
        if (!check.ok()) {
            ++sum.scans_in;
            ++sum.scans_skipped;
            ++sum.skipped_by_reason[static_cast<std::size_t>(check.reject)];
            StreamResult r;
            r.keep = false;
            r.sensor_label = scan.sensorLabel;
            entry_scans.push_back(
                {stampForOutput(stampOf(scan)), scan.sensorLabel, std::move(r), odo, check.reject});
            return false;
        }
        StreamResult r = prefilter.process(scan, odo);
        ++sum.scans_in;
        sum.scans_kept += r.keep;
        sum.points_in += r.report.points_in;
        if (r.keep) sum.points_removed += r.report.points_in - r.report.points_out;
        prefilter_us += r.report.microseconds;
        entry_scans.push_back({stampForOutput(stampOf(scan)), scan.sensorLabel, std::move(r), odo});
        return entry_scans.back().r.keep;
    };
    auto timed = [&](auto&& process) {
        const auto t0 = std::chrono::steady_clock::now();
        process();
        builder_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };

    StartSkipper skipper(opts.skip_scans);
    mrpt::obs::CActionCollection no_odometry;  // laser_only: what the builder gets (empty)
    while (nextEntry(*source, e)) {
        throwIfCancelled();
        if (!steps.feed(e, step) || e.objects_read < rawlog_offset || skipper.skip(step)) continue;
        entry_scans.clear();
        if (step.observation) {
            bool process = true;
            if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(step.observation))
                process = prefilterScan(*scan);
            else if (const auto* odo = dynamic_cast<const mrpt::obs::CObservationOdometry*>(
                         step.observation.get()))
                process = !opts.laser_only &&
                          finitePose(odo->odometry.x(), odo->odometry.y(), odo->odometry.phi());
            if (process) timed([&] { builder.processObservation(step.observation); });
        } else {
            for (auto it = step.frame->begin(); it != step.frame->end();) {
                auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(*it);
                if (scan && !prefilterScan(*scan))
                    it = step.frame->erase(it);
                else
                    ++it;
            }
            // odometry kept even if the frame is empty; a non-finite odometry action is left out
            // (the map builder then matches without a motion prior)
            mrpt::obs::CActionCollection* action =
                opts.laser_only ? &no_odometry : step.action.get();
            mrpt::obs::CActionCollection finite_actions;
            if (auto mv = action->getBestMovementEstimation()) {
                const auto d = mv->rawOdometryIncrementReading;
                const auto m = mv->poseChange ? mv->poseChange->getMeanVal() : d;
                if (!finitePose(d.x(), d.y(), d.phi()) || !finitePose(m.x(), m.y(), m.phi())) {
                    for (std::size_t k = 0; k < action->size(); ++k)
                        if (action->get(k).get() != mv.get())
                            finite_actions.insert(*action->get(k));
                    action = &finite_actions;
                }
            }
            timed([&] { builder.processActionObservation(*action, *step.frame); });
        }
        const auto pose = builder.getCurrentPoseEstimation()->getMeanVal();
        std::snprintf(buf, sizeof(buf), "%i %f %f %f\n", static_cast<int>(step_no), pose.x(),
                      pose.y(), pose.yaw());
        f_path << buf;
        for (const auto& s : entry_scans) {
            if (s.r.keep) res.keyframes.push_back(traj.size());
            if (s.odometry) res.odometry.push_back(StampedPose{s.t, *s.odometry});
            traj.push_back(StampedPose{s.t, Pose2D{pose.x(), pose.y(), pose.yaw()}});
            const auto& rep = s.r.report;
            const auto* kf = rep.find<KeyframeDecision>();
            if (kf && kf->corridor) {
                res.corridor.push_back(traj.size());
                ++sum.scans_corridor;
            }
            const std::string skipped = s.skipped != ScanSkipReason::None
                                            ? std::string("skipped:") + toString(s.skipped)
                                            : std::string();
            std::snprintf(buf, sizeof(buf),
                          "%zu,%.6f,%s,%d,%s,%.6f,%zu,%zu,%.2f,%.6f,%.6f,%.6f,%.4f,%.4f,%d\n",
                          traj.size() - 1, s.t, s.sensor.c_str(), s.r.keep ? 1 : 0,
                          !skipped.empty() ? skipped.c_str()
                          : kf             ? toString(kf->reason)
                                           : (s.r.keep ? "kept" : rep.dropped_by.c_str()),
                          kf ? kf->p_common : 0.0, rep.points_in, rep.points_in - rep.points_out,
                          rep.microseconds, pose.x(), pose.y(), pose.yaw(),
                          kf ? kf->view_change : 0.0, kf ? kf->degeneracy : 1.0,
                          kf && kf->corridor ? 1 : 0);
            f_csv << buf;
        }
        ++step_no;
        ++sum.entries;
        if (opts.on_progress && step_no % 500 == 0)
            opts.on_progress({sum.entries, sum.scans_in, sum.scans_kept,
                              static_cast<double>(source->bytesRead()) / total_bytes});
    }
    if (sum.entries == 0) throw SlamError("no entries in " + sum.rawlog + ": not a rawlog?");
    if (opts.on_progress) opts.on_progress({sum.entries, sum.scans_in, sum.scans_kept, 1.0});
    f_path.close();
    f_csv.close();
    if (f_path.fail() || f_csv.fail()) throw SlamError("cannot write into " + out.string());
    writeTum((out / "trajectory.tum").string(), traj);

    if (!opts.ground_truth_tum.empty()) {
        Trajectory sorted = traj;
        sortByTime(sorted);
        sum.ate_rmse = computeAte(sorted, res.ground_truth, opts.relations_max_dt).rmse;
    }
    if (opts.write_map) {
        res.map.emplace();
        builder.getCurrentlyBuiltMap(*res.map);
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
        // EvalError when no relation matched (never a perfect 0.0)
        sum.relations = evaluateRelations(sorted, relations, opts.relations_max_dt);
        sum.relations_file = opts.relations;
        // Local and long relations; a subset that is empty or matched nothing stays absent.
        const RelationsByLength split = splitRelations(relations, opts.split_seconds);
        sum.relations_local_count = split.local.size();
        sum.relations_long_count = split.far.size();
        auto subset = [&](const std::vector<Relation>& r) -> std::optional<RelationsError> {
            if (r.empty()) return std::nullopt;
            try {
                return evaluateRelations(sorted, r, opts.relations_max_dt);
            } catch (const EvalError&) {
                return std::nullopt;  // none of this subset matched
            }
        };
        sum.relations_local = subset(split.local);
        sum.relations_long = subset(split.far);
    }
    sum.scans_skipped_start = skipper.skipped();
    sum.cpu_s_total = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    sum.wall_s_total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    return res;
}

}  // namespace kfd
