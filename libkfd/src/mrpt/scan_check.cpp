#include "kfd/mrpt/scan_check.h"

#include <cmath>

namespace kfd {

ScanCheck checkScan(mrpt::obs::CObservation2DRangeScan& obs, std::optional<Pose2D>* odometry) {
    ScanCheck c;
    if (odometry && *odometry) {
        const Pose2D& p = **odometry;
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.phi)) {
            odometry->reset();
            c.bad_odometry = true;
        }
    }
    const std::size_t n = obs.getScanSize();
    ScanGeometry g;
    g.beams = n;
    g.aperture = obs.aperture;
    c.reject = checkGeometry(g);
    if (!c.ok()) return c;
    for (std::size_t i = 0; i < n; ++i) {
        if (!obs.getScanRangeValidity(i)) continue;
        const float r = obs.getScanRange(i);
        if (!isUsableRange(r)) {
            obs.setScanRangeValidity(i, false);
            ++c.bad_ranges;
        }
    }
    return c;
}

}  // namespace kfd
