#include "kfd/filters/angle_bounds.h"

#include <cmath>
#include <string>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/stage_keys.h"

namespace kfd {

void AngleBounds::initialize(const Params& p) {
    if (!(p.lower_deg >= -180.0 && p.lower_deg <= p.upper_deg && p.upper_deg <= 180.0))
        throw ParameterError("lower_deg", "angle bounds: need -180 <= lower_deg (" +
                                              keys::formatReal(p.lower_deg) + ") <= upper_deg (" +
                                              keys::formatReal(p.upper_deg) + ") <= 180");
    params_ = p;
}

AngleBounds::Result AngleBounds::filter(Scan& scan) const {
    Result r;
    // 1e-6 rad of slack: MRPT keeps the aperture as a float, so a 180-degree scanner's edge
    // beam lies ~1e-7 rad beyond +-90 degrees; bounds of +-90 keep it.
    constexpr double kSlack = 1e-6;
    const double lo = params_.lower_deg * kPi / 180.0 - kSlack;
    const double hi = params_.upper_deg * kPi / 180.0 + kSlack;
    for (std::size_t i = 0; i < scan.size(); ++i) {
        if (!scan.valid[i]) continue;
        ++r.points_in;
        const double a = std::remainder(scan.geometry.angle(i), 2.0 * kPi);
        const bool inside = a >= lo && a <= hi;
        if (inside == params_.remove_inside) {
            scan.valid[i] = 0;
            ++r.points_removed;
        }
    }
    return r;
}

std::vector<StageKey> AngleBoundsStage::keys() {
    using P = Params;
    return {keys::real<P>("angle_lower_deg", "lower_deg",
                          "angle_bounds: lowest kept beam direction (deg, 0 = forward, "
                          "counter-clockwise positive)",
                          -180, 180, false, [](P& p) -> double& { return p.lower_deg; }),
            keys::real<P>("angle_upper_deg", "upper_deg",
                          "angle_bounds: highest kept beam direction (deg)", -180, 180, false,
                          [](P& p) -> double& { return p.upper_deg; }),
            keys::boolean<P>("angle_remove_inside", "remove_inside",
                             "angle_bounds: remove the beams inside the bounds instead",
                             [](P& p) -> bool& { return p.remove_inside; })};
}

std::vector<StageColumn> AngleBoundsStage::columns() {
    using R = AngleBounds::Result;
    return {diagnosticColumn<R>("removed_angle", "beams removed by the angular bounds", "%zu",
                                [](const R& r) { return r.points_removed; })};
}

std::vector<StageCounter> AngleBoundsStage::counters() {
    using R = AngleBounds::Result;
    return {diagnosticCounter<R>("points_removed_angle",
                                 "points outside the angular bounds removed from kept scans", true,
                                 [](const R& r) { return r.points_removed; })};
}

}  // namespace kfd
