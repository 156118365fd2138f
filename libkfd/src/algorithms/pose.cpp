#include "kfd/algorithms/pose.h"

#include <cmath>

namespace kfd {

Pose2D compose(const Pose2D& a, const Pose2D& b) {
    const double c = std::cos(a.phi), s = std::sin(a.phi);
    return Pose2D{a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, wrapAngle(a.phi + b.phi)};
}

Pose2D inverse(const Pose2D& a) {
    const double c = std::cos(a.phi), s = std::sin(a.phi);
    return Pose2D{-c * a.x - s * a.y, s * a.x - c * a.y, wrapAngle(-a.phi)};
}

Pose2D between(const Pose2D& a, const Pose2D& b) { return compose(inverse(a), b); }

double wrapAngle(double a) {
    a = std::remainder(a, 2.0 * kPi);
    return a <= -kPi ? a + 2.0 * kPi : a;
}

Travel travel(const Pose2D& a, const Pose2D& b) {
    return Travel{std::hypot(b.x - a.x, b.y - a.y),
                  std::abs(wrapAngle(b.phi - a.phi)) * 180.0 / kPi};
}

}  // namespace kfd
