// kfd-icp-slam's re-matching: ICP's verdict on a step, the scans dropped since its last accepted
// correction kept for a re-match, and replayed through ICP after a rejection.
#include "icp_slam_run.h"

namespace kfd::icp_slam {

// The step's correction, if ICP ran: counted, and a streak of rejections is a suspected lost
// track (its first rejection's stamp).
void Run::noteIcp() {
    if (!icp_->ran()) return;
    const double stamp = step_scans_.empty() ? 0.0 : stampForOutput(step_scans_.back().stamp);
    switch (icp_->count(sum_)) {
        case Verdict::Accepted:
            rejected_streak_ = 0;
            rematch_.clear();  // nothing to re-match before an accepted correction
            break;
        case Verdict::Rejected:
            if (rejected_streak_++ == 0) streak_start_ = stamp;
            if (rejected_streak_ == kLostTrackRejections)
                sum_.lost_track_stamps.push_back(streak_start_);
            break;
        case Verdict::GapCheckFailed:  // re-matched (rematch()), not a rejection of the SLAM's
            break;
    }
    recordVerdict();
}

// The step's verdict on its kept scans' records; a rejection starts the recovery.
void Run::recordVerdict() {
    recovering_ = icp_->rejected();
    for (ScanRecord& s : step_scans_)
        if (s.kept) {
            s.icp_goodness = icp_->goodness();
            s.icp_rejected = icp_->rejected();
        }
    icp_->clear();
}

// An odometry reading for the map builder during a re-match: stamped just after the last one
// (its pose estimator wants increasing stamps; without velocities it does not extrapolate).
void Run::feedOdometry(const mrpt::poses::CPose2D& odometry) {
    auto odo = std::make_shared<mrpt::obs::CObservationOdometry>();
    odo->odometry = odometry;
    builder_odometry_t_ += std::chrono::microseconds(1);
    odo->timestamp = builder_odometry_t_;
    timed([&] { builder_.processObservation(odo); });
}

// After ICP rejected the step's correction: the scans dropped since its last accepted one go
// through ICP in their order, each from the odometry the builder had then, and the step's
// kept scans again from their own, so that ICP bridges the odometry in the log's own steps
// (MRPT's builder leaves its map and its last correction untouched by a rejection). Their
// rows say "icp_rematch". No replay of a replay: rematch_ is emptied either way.
void Run::rematch(const IcpSlamStep& st) {
    if (!recovering_ || rematch_.empty()) return;
    ++rematches_;
    const auto pose_now = [&] {
        const auto m = builder_.getCurrentPoseEstimation()->getMeanVal();
        return Pose2D{m.x() + res_.map_origin.x, m.y() + res_.map_origin.y, m.yaw()};
    };
    bool corrected = false;  // did a replayed scan move the pose?
    for (const RematchScan& h : rematch_) {
        if (h.row >= unwritten_.size()) break;  // the step's own (a frame of several scans)
        if (h.odometry) feedOdometry(*h.odometry);
        icp_->clear();
        timed([&] { builder_.processObservation(h.scan); });
        UnwrittenRow& row = unwritten_[h.row];
        row.record.kept = true;
        row.record.reason = "icp_rematch";
        if (icp_->ran()) {
            const bool accepted = icp_->count(sum_) == Verdict::Accepted;
            corrected = corrected || accepted;
            row.record.icp_goodness = icp_->goodness();
            row.record.icp_rejected = icp_->rejected();
        }
        row.pose = pose_now();
        res_.trajectory[row.trajectory_index].pose = row.pose;
        res_.keyframes.push_back(row.trajectory_index);
        ++kept_for_rematch_;
    }
    rematch_.clear();
    // Nothing corrected (every replay rejected, or under the SLAM's gate): the same prior on
    // the same map would give the same fit; the scan stays rejected and the recovery goes on.
    if (!corrected) return;
    if (builder_odometry_) feedOdometry(*builder_odometry_);
    icp_->clear();
    if (st.observation)
        timed([&] { builder_.processObservation(st.observation); });
    else
        for (const auto& o : *st.frame)
            if (IS_CLASS(*o, CObservation2DRangeScan))
                timed([&] { builder_.processObservation(o); });
    if (!icp_->ran()) return;
    if (icp_->count(sum_) == Verdict::Accepted) {
        ++rematches_recovered_;
        rejected_streak_ = 0;
    }
    recordVerdict();
}

// A scan as the door decided it (final); true when it goes on to ICP. Its record waits for the
// step's pose. Applied in the step's builder phase: the recovery reads the builder's state.
bool Run::admitScan(DoorScan& r) {
    const CObservation2DRangeScan::Ptr& scan = r.scan;
    if (!r.keep && recovering_ && r.skipped == ScanSkipReason::None) {
        // Dropped by the pre-filter while ICP is recovering from a rejected correction: it
        // goes to the map builder all the same (as cleaned by the stages that ran).
        r.keep = r.record.kept = true;
        r.record.reason = "icp_recovery";
        ++kept_for_recovery_;
    }
    if (!r.keep && r.skipped == ScanSkipReason::None) {
        // kept for a re-match (a frame's odometry follows with its action: step())
        if (rematch_.size() == kMaxRematch) {  // a long gap: the oldest rows go out, none kept
            rematch_.clear();
            flushUnwritten();
        }
        const TrackResult* t = r.record.report.find<TrackResult>();
        rematch_.push_back(
            {scan, builder_odometry_, unwritten_.size() + step_scans_.size(), t && t->tracked()});
        ++rematch_this_step_;
    }
    step_scans_.push_back(std::move(r.record));
    return r.keep;
}

}  // namespace kfd::icp_slam
