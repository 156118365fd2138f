#include "kfd/live/live_filter.h"

#include <boost/make_shared.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

#include "kfd/io/laser_scan.h"
#include "kfd/mrpt/default_stages.h"

namespace kfd::live {

std::string frameLabel(const std::string& frame_id) { return frameWithoutSlash(frame_id); }

std::vector<std::pair<std::string, double>> counterValues(const LiveCounters& c) {
    const double dropped =
        c.scans_in ? 100.0 * double(c.scans_in - c.scans_kept) / double(c.scans_in) : 0.0;
    return {{"scans_in", double(c.scans_in)},
            {"scans_kept", double(c.scans_kept)},
            {"dropped_pct", dropped},
            {"points_removed", double(c.points_removed)},
            {"out_of_order", double(c.out_of_order)},
            {"odom_missing", double(c.odom_missing)},
            {"resets", double(c.resets)},
            {"geometry_resets", double(c.geometry_resets)},
            {"scans_skipped", double(c.scans_skipped)},
            {"stamps_unusable", double(c.stamps_unusable)},
            {"callback_errors", double(c.callback_errors)},
            {"sensors_evicted", double(c.sensors_evicted)},
            {"scans_missing", double(c.scans_missing)}};
}

std::vector<std::string> attention(const LiveCounters& c, bool odom_expected) {
    std::vector<std::string> out;
    const auto add = [&out](std::size_t n, const std::string& what) {
        if (n) out.push_back(std::to_string(n) + " " + what);
    };
    add(c.scans_missing, "scans missing (gaps in header.seq)");
    if (odom_expected) add(c.odom_missing, "scans without odometry (odom_missing)");
    add(c.stamps_unusable, "scans with an unusable stamp");
    add(c.scans_skipped, "scans of unusable geometry");
    add(c.callback_errors, "messages whose handling failed");
    add(c.sensors_evicted, "frames evicted (more than ~max_sensors)");
    return out;
}

bool usableStamp(double seconds) {
    return std::isfinite(seconds) && seconds >= 0.0 && seconds <= 4294967295.0 - kStampMargin;
}

bool LiveFilter::acceptStamp(double stamp) {
    if (usableStamp(stamp)) return true;
    ++counters_.scans_in;
    ++counters_.stamps_unusable;
    return false;
}

void LiveFilter::countError(bool scan) {
    if (scan) ++counters_.scans_in;
    ++counters_.callback_errors;
}

LiveFilter::LiveFilter(const Params& p) : params_(p), door_(p.pipeline, {}, true) {
    door_.setMaxSensors(p.max_sensors);
}

void LiveFilter::reset() {
    door_.reset();  // finishes held keyframes first (queued for takeReady())
    last_stamp_.clear();
}

void LiveFilter::finish() { door_.finish(); }

bool LiveFilter::takeReady(sensor_msgs::LaserScan::Ptr& out) {
    if (ready_.empty()) return false;
    out = std::move(ready_.front());
    ready_.pop_front();
    return true;
}

std::size_t LiveFilter::markKept(sensor_msgs::LaserScan& m,
                                 const mrpt::obs::CObservation2DRangeScan& o) {
    const std::size_t removed = markRemovedBeams(m, o, params_.removed);
    ++counters_.scans_kept;
    counters_.points_removed += removed;
    return removed;
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
    if (last == last_stamp_.end() && last_stamp_.size() >= door_.maxSensors()) {
        // Bounded like the door's sensors: the frame heard from longest ago is forgotten.
        auto oldest = last_stamp_.begin();
        for (auto it = last_stamp_.begin(); it != last_stamp_.end(); ++it)
            if (it->second < oldest->second) oldest = it;
        last_stamp_.erase(oldest);
    }
    last_stamp_[label] = stamp;
    if (odom_expected && !odometry) ++counters_.odom_missing;
    auto obs = laserScanToObservation(m, stamp, label, mount);
    auto d = std::make_shared<Delivery>();
    r.stream = door_.process(*obs, odometry, [this, obs, d](StreamResult& done) {
        d->finished = true;
        d->keep = done.keep;
        if (d->copy && done.keep) {  // finished later: the copy goes out marked
            markKept(*d->copy, *obs);
            ready_.push_back(d->copy);
        }
    });
    if (r.stream.geometry_reset) ++counters_.geometry_resets;
    counters_.sensors_evicted = door_.counters().sensors_evicted;
    if (r.stream.skipped != ScanSkipReason::None) ++counters_.scans_skipped;
    if (!r.stream.keep) return r;
    if (!d->finished) {  // published once finished: a copy as received
        r.pending = true;
        d->copy = boost::make_shared<sensor_msgs::LaserScan>(m);
        return r;
    }
    r.removed = markKept(m, *obs);
    r.publish = true;
    return r;
}

}  // namespace kfd::live
