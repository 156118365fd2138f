#include "kfd/mrpt/scan_adapter.h"

#include <stdexcept>

#include "kfd/mrpt/source.h"

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
    out.range.resize(n);
    out.valid.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        out.range[i] = obs.getScanRange(i);
        out.valid[i] = obs.getScanRangeValidity(i) ? 1 : 0;
    }
    out.timestamp = stampOf(obs);
    out.sensor_pose = Pose2D{obs.sensorPose.x(), obs.sensorPose.y(), obs.sensorPose.yaw()};
}

std::size_t applyValidity(const Scan& scan, mrpt::obs::CObservation2DRangeScan& obs) {
    const std::size_t n = obs.getScanSize();
    if (scan.valid.size() != n) throw ScanError("applyValidity: beam count differs");
    std::size_t changed = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!scan.valid[i] && obs.getScanRangeValidity(i)) {
            obs.setScanRangeValidity(i, false);
            ++changed;
        }
    }
    return changed;
}

}  // namespace kfd
