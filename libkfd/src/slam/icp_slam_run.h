// One kfd-icp-slam run (IcpSlamRunner::run), as a story of rooms: prepare (run_config.h), the
// drop-rate pre-pass (drop_rate_match.h), the map builder, the loop over icp-slam's steps
// (icp_slam_steps.h) with the door's two phases (icp_slam_runner.cpp), ICP's verdicts
// (icp_verdicts.h) and re-matching (run_rematch.cpp), the outputs (run_outputs.cpp) and the
// evaluation (slam_evaluation.h). Internal to kfd_slam.
#pragma once

#include "kfd/slam/icp_slam_runner.h"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDF.h>
#include <mrpt/slam/CMetricMapBuilderICP.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "kfd/baselines/decimate_stage.h"
#include "kfd/baselines/motion_stage.h"
#include "kfd/eval/ate.h"
#include "kfd/io/open_source.h"
#include "kfd/io/scan_csv.h"
#include "kfd/io/source.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/scan_check.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/os/cancel.h"
#include "kfd/pipeline/format.h"
#include "kfd/slam/gap_check.h"
#include "kfd/stages/keyframe_stage.h"
#include "kfd/stages/track_stage.h"

#include "drop_rate_match.h"
#include "icp_slam_steps.h"
#include "icp_verdicts.h"
#include "run_config.h"
#include "slam_evaluation.h"

namespace kfd::icp_slam {

namespace fs = std::filesystem;
using mrpt::obs::CObservation2DRangeScan;

// At most this many dropped scans wait for a re-match (since ICP's last accepted correction).
constexpr std::size_t kMaxRematch = 64;

// Runs fn, a call into MRPT; what MRPT throws becomes a SlamError that says what kfd was doing
// (doing(), called only then), then MRPT's message (kfd::plainMessage: no banner, no stack).
template <class Fn, class Doing>
void callMrpt(Fn&& fn, Doing&& doing, const std::string& field) {
    try {
        fn();
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw;
    } catch (const std::exception& e) {
        throw SlamError(doing() + ": " + plainMessage(e.what()), field);
    }
}

// One kfd-icp-slam run, as steps: prepare (configuration, paths, pre-filter, pre-pass, ground
// truth), the map builder, the output files, the loop over icp-slam's steps, evaluate.
class Run {
  public:
    explicit Run(const IcpSlamOptions& o) : opts_(o), sum_(res_.summary) {}

    IcpSlamResult execute() {
        const auto wall0 = std::chrono::steady_clock::now();
        const std::clock_t cpu0 = std::clock();
        checkIcpSlamOptions(opts_);
        prepare();
        matchDropRate(opts_, kfd_params_, sum_);
        readGroundTruth();
        StreamFilter prefilter(sum_.pipeline, {}, /*one_scan_latency=*/true);  // next_scan
        prefilter.setLaserOnly(opts_.laser_only);
        prefilter_ = &prefilter;
        initBuilder();
        openOutputs();
        loop();
        closeOutputs();
        evaluate();
        sum_.cpu_s_total = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
        sum_.wall_s_total =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
        return std::move(res_);
    }

  private:
    void prepare();
    void readGroundTruth();
    void initBuilder();
    void openOutputs();
    void loop();
    // A step in two phases. The pre-filter phase (prefilterStep: the door for its scans)
    // hands the builder phase (runStep: the map builder, its verdict, the re-match, the step's
    // outputs) to the door, which runs it once the step's scans are finished: at once, or,
    // with next_scan, when the sensor's next scan finishes a kept one (the steps after it wait
    // behind it, in input order).
    struct DoorScan {
        CObservation2DRangeScan::Ptr scan;  // kept alive (and unchanged) until finished
        bool keep = false;
        ScanSkipReason skipped = ScanSkipReason::None;
        ScanRecord record;  // the door's finished record
    };
    struct DoorStep {
        IcpSlamStep step;
        std::vector<DoorScan> scans;  // the step's 2D scans, in the step's order
    };
    void prefilterStep(const IcpSlamStep& step, const SourceEntry& e);
    void runStep(DoorStep& w);
    void step(DoorStep& w);
    template <class Process>
    void timed(Process&& process);
    template <class Process>
    void match(bool after_drops, Process&& process);
    void feedOdometry(const mrpt::poses::CPose2D& odometry);
    void feedTrack(const DoorScan& d);
    bool gapToBridge(std::size_t own) const;
    void rematch(const IcpSlamStep& step);
    bool toMapFrame(mrpt::obs::CObservationOdometry& odo);
    bool admitScan(DoorScan& d);
    mrpt::obs::CActionCollection* actionFor(const IcpSlamStep& step);
    void writeStep(double builder_ms);
    void closeOutputs();
    void evaluate();

    const IcpSlamOptions& opts_;
    IcpSlamResult res_;
    IcpSlamSummary& sum_;
    std::optional<mrpt::config::CConfigFile> cfg_;
    Pipeline::Params kfd_params_;  // [KFD], or kfd's defaults
    std::vector<Relation> relations_;
    StreamFilter* prefilter_ = nullptr;
    mrpt::slam::CMetricMapBuilderICP builder_;
    std::size_t rawlog_offset_ = 0;
    IcpSlamLogParams log_params_;      // [MappingApplication]'s output keys
    std::optional<IcpSlamLogs> logs_;  // icp-slam's files
    ScanCsvWriter csv_;                // scans.csv
    std::unique_ptr<Source> source_;
    double builder_s_ = 0.0;
    std::size_t step_no_ = 0;
    std::vector<ScanRecord> step_scans_;        // the scans of the current step, in order
    mrpt::obs::CActionCollection no_odometry_;  // laser_only: what the builder gets (empty)
    mrpt::obs::CActionCollection finite_actions_;
    bool origin_set_ = false;  // the first absolute odometry set res_.map_origin
    // The pipeline lists the track stage: the map builder's odometry is the track (each scan's
    // tracked pose, kept or dropped), not the log's (issue 35).
    bool tracking_ = false;
    // ICP's correction of the current step and every one counted (icp_verdicts.h).
    std::optional<IcpVerdicts> icp_;
    using Verdict = IcpVerdicts::Verdict;
    void noteIcp();
    void recordVerdict();
    std::size_t rejected_streak_ = 0;
    double streak_start_ = 0.0;
    // After ICP rejected a correction, every scan goes to the map builder until it accepts one
    // again: the pre-filter's drops never widen the gap a struggling ICP has to bridge.
    bool recovering_ = false;
    std::size_t kept_for_recovery_ = 0;
    // Re-matching (rematch()): the scans the pre-filter dropped since ICP last accepted a
    // correction, each with the odometry the map builder had then; after a rejected correction
    // they go through ICP in order, then the rejected scan again. Their scans.csv rows wait in
    // unwritten_ (from the first scan kept for a re-match on) until ICP accepts a correction or
    // they are replayed.
    struct RematchScan {
        CObservation2DRangeScan::Ptr scan;
        std::optional<mrpt::poses::CPose2D> odometry;  // the builder's, when it had one
        std::size_t row;                               // its entry in unwritten_
        bool tracked = false;                          // the tracker aligned it to its keyframe
    };
    struct UnwrittenRow {
        ScanRecord record;
        Pose2D pose;
        std::size_t trajectory_index;
    };
    std::vector<RematchScan> rematch_;
    std::size_t rematch_this_step_ = 0;  // rematch_ entries added by the current step
    std::vector<UnwrittenRow> unwritten_;
    void flushUnwritten();
    // The odometry the map builder last got (MRPT's CMetricMapBuilderICP accumulates the
    // actions' pose changes, or takes an odometry observation as it is), and its stamp.
    std::optional<mrpt::poses::CPose2D> builder_odometry_;
    mrpt::Clock::time_point builder_odometry_t_{};
    std::size_t rematches_ = 0, rematches_recovered_ = 0, kept_for_rematch_ = 0;
};

// A call into the map builder, timed; what it throws names the step, its last scan's stamp
// and the log.
template <class Process>
void Run::timed(Process&& process) {
    const auto t0 = std::chrono::steady_clock::now();
    callMrpt(
        process,
        [&] {
            char where[96];
            std::snprintf(where, sizeof(where), "MRPT's ICP map builder failed at step %zu",
                          step_no_);
            std::string doing = where;
            if (!step_scans_.empty()) {
                std::snprintf(where, sizeof(where), " (scan at t = %.6f s)",
                              step_scans_.back().stamp);
                doing += where;
            }
            return doing + " of " + sum_.rawlog;
        },
        sum_.rawlog);
    builder_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A call into the map builder with the step's scans; after drops (scans kept for a re-match since
// ICP's last accepted correction, from earlier steps) under the gap check's minimum for that one
// call.
template <class Process>
void Run::match(bool after_drops, Process&& process) {
    if (after_drops) builder_.ICP_options.minICPgoodnessToAccept = icp_->gapMinimum();
    timed(process);
    builder_.ICP_options.minICPgoodnessToAccept = icp_->minimum();
}

}  // namespace kfd::icp_slam
