#include "kfd/mrpt/scan_adapter.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "kfd/io/source.h"

namespace kfd {

ScanGeometry geometryOf(const mrpt::obs::CObservation2DRangeScan& obs) {
    ScanGeometry g;
    g.beams = obs.getScanSize();
    g.aperture = obs.aperture;
    g.right_to_left = obs.rightToLeft;
    return g;
}

void toCore(const mrpt::obs::CObservation2DRangeScan& obs, Scan& out) {
    const std::size_t n = obs.getScanSize();
    out.geometry = geometryOf(obs);
    out.valid.resize(n);
    if (n == 0) {
        out.range.clear();
    } else {  // MRPT keeps the ranges contiguous: one copy (its validity has no such accessor)
        const float* r = &obs.getScanRange(0);
        out.range.assign(r, r + n);
    }
    std::uint8_t* valid = out.valid.data();
    for (std::size_t i = 0; i < n; ++i) valid[i] = obs.getScanRangeValidity(i) ? 1 : 0;
    out.intensity.clear();
    if (obs.hasIntensity() && n > 0) {
        out.intensity.resize(n);
        for (std::size_t i = 0; i < n; ++i)
            out.intensity[i] = static_cast<float>(obs.getScanIntensity(i));
    }
    out.timestamp = stampOf(obs);
    out.sensor_pose = Pose2D{obs.sensorPose.x(), obs.sensorPose.y(), obs.sensorPose.yaw()};
    out.max_range = obs.maxRange > 0.0f && std::isfinite(obs.maxRange)
                        ? obs.maxRange
                        : std::numeric_limits<float>::infinity();
}

}  // namespace kfd
