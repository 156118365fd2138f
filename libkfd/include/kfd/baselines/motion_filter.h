// Odometry motion filter (baseline, beyond the paper): keep a scan only after enough motion.
#pragma once

#include <optional>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Like Cartographer's motion filter: a scan is kept when the robot has moved at least
/// max_distance_m or turned at least max_angle_deg since the last kept scan, or when
/// max_interval_s has passed (each 0 = that test off). The first scan is always kept; a scan
/// without odometry is kept (nothing to compare) and does not become the reference. The
/// interval test needs a reference with a known (finite) timestamp. The baseline that kfd's
/// keyframe extraction must beat at an equal drop rate.
class MotionFilter {
  public:
    struct Params {
        double max_distance_m = 0.2;  // m
        double max_angle_deg = 10.0;  // deg
        double max_interval_s = 0.0;  // s, 0 = off
    };

    MotionFilter() = default;
    explicit MotionFilter(const Params& p) { initialize(p); }
    /// Throws kfd::ParameterError on negative or non-finite values.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    /// True when the scan is to be kept (and then becomes the new reference).
    bool keep(double timestamp, const std::optional<Pose2D>& odometry);
    void reset() {
        have_ref_ = false;
        have_stamp_ = false;
    }

  private:
    Params params_;
    bool have_ref_ = false;
    double ref_stamp_ = 0.0;
    bool have_stamp_ = false;  // the reference scan had a finite timestamp
    Pose2D ref_pose_;
};

}  // namespace kfd
