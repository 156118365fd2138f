#include "kfd/baselines/motion_filter.h"

#include <cmath>
#include "kfd/algorithms/pose.h"
#include "kfd/pipeline/error.h"

namespace kfd {

void MotionFilter::initialize(const Params& p) {
    auto ok = [](double v) { return v >= 0.0 && std::isfinite(v); };
    if (!ok(p.max_distance_m))
        throw ParameterError("max_distance_m", "motion_distance_m must be >= 0");
    if (!ok(p.max_angle_deg))
        throw ParameterError("max_angle_deg", "motion_angle_deg must be >= 0");
    if (!ok(p.max_interval_s))
        throw ParameterError("max_interval_s", "motion_interval_s must be >= 0");
    params_ = p;
    reset();
}

bool MotionFilter::keep(double timestamp, const std::optional<Pose2D>& odometry) {
    if (!odometry) return true;
    bool take = !have_ref_;
    if (!take) {
        const Travel t = travel(ref_pose_, *odometry);
        take = (params_.max_distance_m > 0.0 && t.metres >= params_.max_distance_m) ||
               (params_.max_angle_deg > 0.0 && t.degrees >= params_.max_angle_deg) ||
               (params_.max_interval_s > 0.0 && have_stamp_ && std::isfinite(timestamp) &&
                timestamp - ref_stamp_ >= params_.max_interval_s);
    }
    if (take) {
        have_ref_ = true;
        ref_pose_ = *odometry;
        // An unknown time at the reference leaves the interval test without a reference.
        have_stamp_ = std::isfinite(timestamp);
        ref_stamp_ = have_stamp_ ? timestamp : 0.0;
    }
    return take;
}

}  // namespace kfd
