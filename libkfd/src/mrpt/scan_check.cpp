#include "kfd/mrpt/scan_check.h"

#include <cmath>
#include <cstdint>

#include "kfd/mrpt/scan_adapter.h"

namespace kfd {

bool checkOdometry(std::optional<Pose2D>& odometry) {
    if (!odometry) return false;
    const Pose2D& p = *odometry;
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.phi)) return false;
    odometry.reset();
    return true;
}

ScanCheck checkScan(mrpt::obs::CObservation2DRangeScan& obs, std::optional<Pose2D>* odometry,
                    Scan& core) {
    ScanCheck c;
    if (odometry) c.bad_odometry = checkOdometry(*odometry);
    ScanGeometry g;
    g.beams = obs.getScanSize();
    g.aperture = obs.aperture;
    c.reject = checkGeometry(g);
    if (!c.ok()) return c;
    // One pass over the core copy; the MRPT scan is written only where a beam is bad.
    toCore(obs, core);
    const float* range = core.range.data();
    std::uint8_t* valid = core.valid.data();
    for (std::size_t i = 0, n = core.size(); i < n; ++i) {
        if (!valid[i] || isUsableRange(range[i])) continue;
        valid[i] = 0;
        obs.setScanRangeValidity(i, false);
        ++c.bad_ranges;
    }
    return c;
}

ScanCheck checkScan(mrpt::obs::CObservation2DRangeScan& obs, std::optional<Pose2D>* odometry) {
    Scan core;
    return checkScan(obs, odometry, core);
}

}  // namespace kfd
