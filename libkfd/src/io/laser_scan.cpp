#include "kfd/io/laser_scan.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

namespace kfd {

std::string frameWithoutSlash(const std::string& frame_id) {
    const auto b = frame_id.find_first_not_of('/');
    return b == std::string::npos ? std::string() : frame_id.substr(b);
}

double quaternionYaw(const geometry_msgs::Quaternion& q) {
    return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

bool validRange(const sensor_msgs::LaserScan& m, float r) {
    return std::isfinite(r) && r >= m.range_min && r < m.range_max;
}

bool laserAnglesMatch(const sensor_msgs::LaserScan& m) {
    const std::size_t n = m.ranges.size();
    if (n < 2) return true;
    const double lo = m.angle_min, hi = m.angle_max, inc = m.angle_increment;
    if (!std::isfinite(lo) || !std::isfinite(hi) || !std::isfinite(inc) || inc == 0.0) return false;
    return std::fabs((hi - lo) / inc - static_cast<double>(n - 1)) <= 1.0 || fullTurnSpan(m);
}

bool fullTurnSpan(const sensor_msgs::LaserScan& m) {
    const std::size_t n = m.ranges.size();
    const double span = double(m.angle_max) - double(m.angle_min), inc = m.angle_increment;
    return n >= 2 && inc != 0.0 && std::isfinite(span / inc) &&
           std::fabs(span / inc - static_cast<double>(n)) <= 1e-3;
}

mrpt::obs::CObservation2DRangeScan::Ptr laserScanToObservation(const sensor_msgs::LaserScan& m,
                                                               double stamp,
                                                               const std::string& label,
                                                               const Pose2D& mount) {
    auto obs = std::make_shared<mrpt::obs::CObservation2DRangeScan>();
    obs->sensorLabel = label;
    obs->timestamp = mrpt::Clock::fromDouble(stamp);
    const std::size_t n = m.ranges.size();
    const bool angles_ok = laserAnglesMatch(m);
    // The beams' span: angle_max - angle_min, or (n - 1) increments when angle_max is one
    // increment past the last beam (fullTurnSpan).
    const double last = fullTurnSpan(m)
                            ? double(m.angle_min) + double(n - 1) * double(m.angle_increment)
                            : double(m.angle_max);
    obs->aperture = angles_ok ? static_cast<float>(std::fabs(last - double(m.angle_min)))
                              : std::numeric_limits<float>::quiet_NaN();
    obs->rightToLeft = !angles_ok || m.angle_increment >= 0.0f;
    obs->maxRange = m.range_max;
    const double mid = angles_ok ? 0.5 * (double(m.angle_min) + last) : 0.0;
    obs->sensorPose = mrpt::poses::CPose3D(mount.x, mount.y, 0.0, mount.phi + mid, 0.0, 0.0);
    obs->resizeScan(n);
    for (std::size_t i = 0; i < n; ++i) {
        const float r = m.ranges[i];
        obs->setScanRange(i, std::isfinite(r) ? r : 0.0f);
        obs->setScanRangeValidity(i, validRange(m, r));
    }
    if (m.intensities.size() == n && n > 0) {
        obs->setScanHasIntensity(true);
        for (std::size_t i = 0; i < n; ++i)
            obs->setScanIntensity(
                i, static_cast<int32_t>(
                       std::lround(std::isfinite(m.intensities[i]) ? m.intensities[i] : 0.f)));
    }
    return obs;
}

namespace {

// `m` rewritten as `cleaned`, a scan the stages resampled (beam_count): its beams, increment,
// angle_max and intensities; invalid beams hold `value`. Returns how many fewer valid beams
// it has than `m` had.
std::size_t writeResampled(sensor_msgs::LaserScan& m,
                           const mrpt::obs::CObservation2DRangeScan& cleaned, float value) {
    std::size_t valid_before = 0;
    for (const float r : m.ranges) valid_before += validRange(m, r) ? 1 : 0;
    const std::size_t n_before = m.ranges.size(), n = cleaned.getScanSize();
    std::size_t valid_after = 0;
    m.ranges.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const bool valid = cleaned.getScanRangeValidity(i);
        m.ranges[i] = valid ? cleaned.getScanRange(i) : value;
        valid_after += valid ? 1 : 0;
    }
    const double inc = n > 1 ? double(cleaned.aperture) / double(n - 1) : 0.0;
    m.angle_increment = static_cast<float>(cleaned.rightToLeft ? inc : -inc);
    m.angle_max =
        static_cast<float>(double(m.angle_min) + double(m.angle_increment) * double(n - 1));
    if (n_before > 1 && n > 1)
        m.time_increment *= static_cast<float>(double(n_before - 1) / double(n - 1));
    m.intensities.clear();
    if (cleaned.hasIntensity())
        for (std::size_t i = 0; i < n; ++i)
            m.intensities.push_back(static_cast<float>(cleaned.getScanIntensity(i)));
    return valid_before > valid_after ? valid_before - valid_after : 0;
}

}  // namespace

std::size_t markRemovedBeams(sensor_msgs::LaserScan& m,
                             const mrpt::obs::CObservation2DRangeScan& cleaned, RemovedMark mark) {
    const float value = mark == RemovedMark::NaN ? std::numeric_limits<float>::quiet_NaN()
                                                 : std::numeric_limits<float>::infinity();
    if (cleaned.getScanSize() != m.ranges.size()) return writeResampled(m, cleaned, value);
    std::size_t marked = 0;
    const std::size_t n = std::min(m.ranges.size(), cleaned.getScanSize());
    for (std::size_t i = 0; i < n; ++i) {
        if (validRange(m, m.ranges[i]) && !cleaned.getScanRangeValidity(i)) {
            m.ranges[i] = value;
            ++marked;
        }
    }
    return marked;
}

}  // namespace kfd
