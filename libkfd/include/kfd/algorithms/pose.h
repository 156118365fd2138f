// SE(2) helpers on kfd::Pose2D (std only): composition, inverse, relative pose, angle wrap,
// travel.
#pragma once

#include "kfd/pipeline/scan.h"

namespace kfd {

/// a (+) b: b expressed in a's frame, composed onto a.
Pose2D compose(const Pose2D& a, const Pose2D& b);
/// The inverse transform of a.
Pose2D inverse(const Pose2D& a);
/// b in the frame of a: inverse(a) (+) b.
Pose2D between(const Pose2D& a, const Pose2D& b);
/// Wraps an angle into (-pi, pi].
double wrapAngle(double a);

/// How far b lies from a: the distance (m) and the absolute turn (deg, wrapped), what the
/// keyframe guards, the view selector's corridor switch and the motion filter compare with
/// their thresholds.
struct Travel {
    double metres = 0.0;
    double degrees = 0.0;
};
Travel travel(const Pose2D& a, const Pose2D& b);

}  // namespace kfd
