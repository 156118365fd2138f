#include "kfd/live/odometry_buffer.h"

#include <cmath>

#include "kfd/algorithms/pose.h"
#include "kfd/io/source.h"

namespace kfd::live {

void OdometryBuffer::add(double stamp, const Pose2D& pose) {
    if (!std::isfinite(stamp) || !finitePose(pose.x, pose.y, pose.phi)) return;
    if (!samples_.empty() && stamp < samples_.back().t) return;
    samples_.push_back(Sample{stamp, pose});
    while (samples_.size() > params_.capacity) samples_.pop_front();
}

std::optional<Pose2D> OdometryBuffer::at(double t) const {
    if (samples_.empty() || !std::isfinite(t)) return std::nullopt;
    const Sample& last = samples_.back();
    if (last.t < t) {
        if (t - last.t <= params_.hold_seconds) return last.p;
        return std::nullopt;
    }
    std::size_t k = samples_.size() - 1;  // the first sample at or after t, from the back
    while (k > 0 && samples_[k - 1].t >= t) --k;
    const Sample& b = samples_[k];
    if (b.t == t) return b.p;
    if (k == 0) {
        if (b.t - t <= params_.hold_seconds) return b.p;
        return std::nullopt;
    }
    const Sample& a = samples_[k - 1];
    const double w = (t - a.t) / (b.t - a.t);
    return Pose2D{a.p.x + w * (b.p.x - a.p.x), a.p.y + w * (b.p.y - a.p.y),
                  wrapAngle(a.p.phi + w * wrapAngle(b.p.phi - a.p.phi))};
}

}  // namespace kfd::live
