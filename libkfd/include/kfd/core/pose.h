// SE(2) helpers on kfd::Pose2D (std only): composition, inverse, relative pose, angle wrap.
#pragma once

#include "kfd/core/scan.h"

namespace kfd {

/// a (+) b: b expressed in a's frame, composed onto a.
Pose2D compose(const Pose2D& a, const Pose2D& b);
/// The inverse transform of a.
Pose2D inverse(const Pose2D& a);
/// b in the frame of a: inverse(a) (+) b.
Pose2D between(const Pose2D& a, const Pose2D& b);
/// Wraps an angle into (-pi, pi].
double wrapAngle(double a);

}  // namespace kfd
