// kfd-icp-slam's outputs: the staged folder, icp-slam's files, scans.csv, trajectory.tum and
// the summary's figures.
#include "icp_slam_run.h"

namespace kfd::icp_slam {

// Everything is written into a staging folder; writeIcpSlamReport() (or
// result.output->commit()) moves it into place, and on failure it is removed.
void Run::openOutputs() {
    res_.output = std::make_shared<StagedOutputFolder>(sum_.output_dir);
    // Every file through kfd's checked writers: a failed write is a WriteError (ScanCsvError for
    // scans.csv) naming the file's final name and the reason.
    const StagedOutputFolder& out = *res_.output;
    logs_.emplace(out, log_params_);
    csv_.open((out.path() / "scans.csv").string(), out.finalName("scans.csv"),
              prefilter_->outputs());
    source_ = openLog(sum_.rawlog, opts_.source);
}

// The step's pose (icp-slam's files) and, for each of its scans, the trajectory, odometry,
// keyframe and corridor entries and the scans.csv row.
void Run::writeStep(double builder_ms) {
    const auto local = builder_.getCurrentPoseEstimation()->getMeanVal();
    const mrpt::poses::CPose3D pose(local.x() + res_.map_origin.x, local.y() + res_.map_origin.y,
                                    local.z(), local.yaw(), local.pitch(), local.roll());
    logs_->endStep(step_no_, builder_, builder_ms, pose, res_.map_origin);
    const Pose2D p{pose.x(), pose.y(), pose.yaw()};
    Trajectory& traj = res_.trajectory;
    for (const ScanRecord& s : step_scans_) {
        if (s.kept) res_.keyframes.push_back(traj.size());
        if (prefilter_->outputs().cell(s.report, "corridor") == "1")
            res_.corridor.push_back(traj.size());
        const double t = stampForOutput(s.stamp);
        if (s.odometry) res_.odometry.push_back(StampedPose{t, *s.odometry});
        if (const TrackResult* tr = s.report.find<TrackResult>())
            res_.track.push_back(StampedPose{t, tr->pose});
        traj.push_back(StampedPose{t, p});
        unwritten_.push_back({s, p, traj.size() - 1});
    }
    if (rematch_.empty()) flushUnwritten();
}

// The rows waiting for a possible re-match, to scans.csv.
void Run::flushUnwritten() {
    for (const UnwrittenRow& row : unwritten_) csv_.write(row.record, row.pose);
    unwritten_.clear();
}

void Run::closeOutputs() {
    rematch_.clear();
    flushUnwritten();
    std::sort(res_.keyframes.begin(), res_.keyframes.end());
    logs_->finish(builder_, res_.map_origin, opts_.write_map, sum_.notices);
    csv_.close();
    writeTum((res_.output->path() / "trajectory.tum").string(), res_.trajectory,
             res_.output->finalName("trajectory.tum"));
}

// The summary from the door's counters, the map, ATE and the relations error (local and long).
void Run::evaluate() {
    static_cast<ScanCounters&>(sum_) = prefilter_->counters();
    sum_.scans_kept += kept_for_recovery_;  // the door counted them as dropped
    sum_.scans_dropped -= kept_for_recovery_;
    sum_.scans_kept_for_recovery = kept_for_recovery_;
    sum_.scans_kept += kept_for_rematch_;
    sum_.scans_dropped -= kept_for_rematch_;
    sum_.scans_rematched = kept_for_rematch_;
    sum_.rematches = rematches_;
    sum_.rematches_recovered = rematches_recovered_;
    sum_.dropped_pct = sum_.notKeptPercent();
    const double scans_in = static_cast<double>(sum_.scans_in);
    sum_.prefilter_us_per_scan = sum_.scans_in ? 1e6 * sum_.filter_seconds / scans_in : 0;
    sum_.icp_ms_per_scan = sum_.scans_in ? 1e3 * builder_s_ / scans_in : 0;
    sum_.icp_ms_per_kept_scan =
        sum_.scans_kept ? 1e3 * builder_s_ / static_cast<double>(sum_.scans_kept) : 0;
    if (const auto m = icp_->median()) sum_.icp_goodness_median = *m;
    if (opts_.write_map) {
        res_.map.emplace();
        builder_.getCurrentlyBuiltMap(*res_.map);
    }
    evaluateTrajectory(opts_, relations_, res_.trajectory, res_.ground_truth, sum_);
}

}  // namespace kfd::icp_slam
