// Small generated rawlogs with pathological scans, for the scan-validation tests (MRPT + std).
#pragma once

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <functional>
#include <string>

namespace kfd {
namespace test {

/// A 361-beam, 180-degree scan of a 4 x 6 m room seen from (x, 0): enough structure for ICP.
inline void roomScanInto(mrpt::obs::CObservation2DRangeScan& s, double x, double stamp) {
    s.sensorLabel = "LASER";
    s.aperture = static_cast<float>(M_PI);
    s.rightToLeft = true;
    s.maxRange = 80.0f;
    s.timestamp = mrpt::Clock::fromDouble(stamp);
    const std::size_t n = 361;
    s.resizeScan(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double a = -M_PI / 2 + M_PI * static_cast<double>(i) / (n - 1);
        const double c = std::cos(a), sn = std::sin(a);
        double r = 1e9;
        if (c > 1e-9) r = std::min(r, (4.0 - x) / c);  // front wall at x = 4
        if (sn > 1e-9) r = std::min(r, 3.0 / sn);      // side walls at y = +-3
        if (sn < -1e-9) r = std::min(r, -3.0 / sn);
        s.setScanRange(i, static_cast<float>(r));
        s.setScanRangeValidity(i, true);
    }
}

/// Writes an actions + sensory-frames log of `n` steps (0.05 m forward each, 0.2 s apart).
/// `tweak_scan(k, scan)` and `tweak_motion(k, increment)` make step k pathological.
inline void writeRoomLog(
    const std::string& path, int n,
    const std::function<void(int, mrpt::obs::CObservation2DRangeScan&)>& tweak_scan = {},
    const std::function<void(int, mrpt::poses::CPose2D&)>& tweak_motion = {}) {
    mrpt::io::CFileGZOutputStream f(path);
    auto arch = mrpt::serialization::archiveFrom(f);
    for (int k = 0; k < n; ++k) {
        mrpt::poses::CPose2D inc(k == 0 ? 0.0 : 0.05, 0.0, 0.0);
        if (tweak_motion) tweak_motion(k, inc);
        mrpt::obs::CActionCollection acts;
        mrpt::obs::CActionRobotMovement2D mv;
        mv.computeFromOdometry(inc, mrpt::obs::CActionRobotMovement2D::TMotionModelOptions());
        mv.timestamp = mrpt::Clock::fromDouble(1000.0 + 0.2 * k);
        acts.insert(mv);
        arch << acts;
        auto scan = std::make_shared<mrpt::obs::CObservation2DRangeScan>();
        roomScanInto(*scan, 0.05 * k, 1000.0 + 0.2 * k);
        if (tweak_scan) tweak_scan(k, *scan);
        mrpt::obs::CSensoryFrame sf;
        sf.insert(scan);
        arch << sf;
    }
}

/// The same walk as an observations log: each step a CObservationOdometry (absolute pose)
/// then the scan. `tweak_odometry(k, pose)` makes step k's odometry pathological.
inline void writeRoomObservationLog(
    const std::string& path, int n,
    const std::function<void(int, mrpt::obs::CObservation2DRangeScan&)>& tweak_scan = {},
    const std::function<void(int, mrpt::poses::CPose2D&)>& tweak_odometry = {}) {
    mrpt::io::CFileGZOutputStream f(path);
    auto arch = mrpt::serialization::archiveFrom(f);
    for (int k = 0; k < n; ++k) {
        mrpt::obs::CObservationOdometry odo;
        odo.sensorLabel = "ODOMETRY";
        odo.timestamp = mrpt::Clock::fromDouble(1000.0 + 0.2 * k);
        odo.odometry = mrpt::poses::CPose2D(0.05 * k, 0.0, 0.0);
        if (tweak_odometry) tweak_odometry(k, odo.odometry);
        arch << odo;
        mrpt::obs::CObservation2DRangeScan scan;
        roomScanInto(scan, 0.05 * k, 1000.0 + 0.2 * k + 0.01);
        if (tweak_scan) tweak_scan(k, scan);
        arch << scan;
    }
}

}  // namespace test
}  // namespace kfd
