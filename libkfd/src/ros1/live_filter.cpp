#include "kfd/ros1/live_filter.h"

#include "kfd/mrpt/default_stages.h"
#include "kfd/mrpt/laser_scan.h"

namespace kfd::ros1 {

std::string frameLabel(const std::string& frame_id) {
    const auto b = frame_id.find_first_not_of('/');
    return b == std::string::npos ? std::string() : frame_id.substr(b);
}

LiveFilter::LiveFilter(const Params& p) : params_(p), door_(p.pipeline) {}

void LiveFilter::reset() {
    door_.reset();
    last_stamp_.clear();
}

bool LiveFilter::onClock(double now) {
    const bool back = last_clock_ >= 0.0 && now < last_clock_;
    last_clock_ = now;
    if (!back) return false;
    reset();
    ++counters_.resets;
    return true;
}

LiveResult LiveFilter::process(sensor_msgs::LaserScan& m, double stamp,
                               const std::optional<Pose2D>& odometry, bool odom_expected,
                               const Pose2D& mount) {
    LiveResult r;
    ++counters_.scans_in;
    const std::string label = frameLabel(m.header.frame_id);
    const auto last = last_stamp_.find(label);
    if (last != last_stamp_.end() && stamp < last->second) {
        if (last->second - stamp < params_.reset_jump) {
            r.out_of_order = true;
            ++counters_.out_of_order;
            return r;
        }
        reset();
        r.reset = true;
        ++counters_.resets;
    }
    last_stamp_[label] = stamp;
    if (odom_expected && !odometry) ++counters_.odom_missing;
    auto obs = laserScanToObservation(m, stamp, label, mount);
    r.stream = door_.process(*obs, odometry);
    if (r.stream.geometry_reset) ++counters_.geometry_resets;
    if (r.stream.skipped != ScanSkipReason::None) ++counters_.scans_skipped;
    if (!r.stream.keep) return r;
    r.removed = markRemovedBeams(m, *obs, params_.removed);
    r.publish = true;
    ++counters_.scans_kept;
    counters_.points_removed += r.removed;
    return r;
}

}  // namespace kfd::ros1
