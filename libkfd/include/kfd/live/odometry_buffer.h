// The recent odometry samples of a live node (nav_msgs/Odometry on `odom`), bounded, and the
// robot's pose at a scan's stamp from them, by the bag source's rule (kfd-filter -i X.bag).
#pragma once

#include <cstddef>
#include <deque>
#include <limits>
#include <optional>

#include "kfd/pipeline/scan.h"

namespace kfd::live {

/// Bounded buffer of (stamp, pose) samples in arrival order.
class OdometryBuffer {
  public:
    struct Params {
        std::size_t capacity = 512;  // samples kept (the oldest go first); 10 s at 50 Hz
        /// s: a scan up to this long after the newest sample (or before the oldest) takes it;
        /// further away its odometry is unknown (the bag source's kOdometryHoldSeconds).
        double hold_seconds = 1.0;
    };

    OdometryBuffer() = default;
    explicit OdometryBuffer(const Params& p) : params_(p) {}

    /// Adds a sample (s, robot pose in the odometry frame); non-finite ones are ignored. A
    /// sample older than the newest is ignored too (samples stay in time order).
    void add(double stamp, const Pose2D& pose);
    /// The pose at `stamp`: interpolated between the samples around it (yaw the short way),
    /// the sample itself at an equal stamp, the oldest or newest sample within hold_seconds,
    /// else nothing.
    std::optional<Pose2D> at(double stamp) const;
    /// The newest sample's stamp (s); NaN when empty.
    double newest() const {
        return samples_.empty() ? std::numeric_limits<double>::quiet_NaN() : samples_.back().t;
    }
    void clear() { samples_.clear(); }
    std::size_t size() const { return samples_.size(); }
    const Params& params() const { return params_; }

  private:
    struct Sample {
        double t;
        Pose2D p;
    };
    Params params_;
    std::deque<Sample> samples_;
};

}  // namespace kfd::live
