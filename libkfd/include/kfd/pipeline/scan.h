// kfd core: the scan representation shared by every stage (std only).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace kfd {

constexpr double kPi = 3.14159265358979323846;

/// Planar pose (odometry), metres and radians.
struct Pose2D {
    double x = 0.0;    // m
    double y = 0.0;    // m
    double phi = 0.0;  // rad
};

/// Geometry of a 2D range scan, with MRPT's convention (CObservation2DRangeScan::getScanAngle):
/// beam i points at angle(i) = -aperture/2 + i * aperture/(beams-1), mirrored when
/// right_to_left is false.
struct ScanGeometry {
    std::size_t beams = 0;
    double aperture = kPi;  // rad, field of view
    bool right_to_left = true;

    /// Signed angle between consecutive beams (rad).
    double step() const {
        if (beams < 2) return 0.0;
        const double s = aperture / static_cast<double>(beams - 1);
        return right_to_left ? s : -s;
    }
    /// Angular resolution (rad), always >= 0.
    double resolution() const { return std::abs(step()); }
    /// Direction of beam i (rad), 0 = forward.
    double angle(std::size_t i) const {
        const double first = right_to_left ? -0.5 * aperture : 0.5 * aperture;
        return first + step() * static_cast<double>(i);
    }
    /// Angle (rad) between the last beam and the first one going on around the circle
    /// (2*pi - aperture); small for a 360-degree scanner.
    double seamGap() const { return 2.0 * kPi - aperture; }

    bool operator==(const ScanGeometry& o) const {
        return beams == o.beams && aperture == o.aperture && right_to_left == o.right_to_left;
    }
    bool operator!=(const ScanGeometry& o) const { return !(*this == o); }
};

/// The unit direction (cos, sin) of every beam of a geometry, as floats; update() recomputes
/// them only when the geometry changes (per-scan tables of the clustering variants).
struct BeamDirections {
    ScanGeometry geometry;
    std::vector<float> cos, sin;

    void update(const ScanGeometry& g) {
        if (g == geometry && cos.size() == g.beams) return;
        geometry = g;
        cos.resize(g.beams);
        sin.resize(g.beams);
        for (std::size_t i = 0; i < g.beams; ++i) {
            cos[i] = static_cast<float>(std::cos(g.angle(i)));
            sin[i] = static_cast<float>(std::sin(g.angle(i)));
        }
    }
};

/// Limits of a scan's geometry, checked by checkGeometry() (Pipeline::process throws ScanError
/// outside them; the MRPT adapter skips such a scan, kfd/mrpt/scan_check.h).
/// 65 536 beams cover every real 2D lidar (the densest take ~ 10 000 per turn); at least two
/// beams are needed for an angular resolution aperture / (beams - 1).
constexpr std::size_t kMinScanBeams = 2;
constexpr std::size_t kMaxScanBeams = 65536;
/// Largest aperture (rad): one full turn, with a relative slack of 1e-6 for MRPT's float
/// aperture (float(2*pi) is a little above 2*pi).
constexpr double kMaxScanAperture = 2.0 * kPi * (1.0 + 1e-6);
/// Largest range (m) the adapter accepts as a measurement: no 2D lidar measures 10 km; a
/// larger value (e.g. 1e30) is marked invalid like NaN, +-inf and negative ranges.
constexpr float kMaxScanRangeM = 1.0e4f;

/// Why a scan's geometry cannot be used (None: it can).
enum class ScanSkipReason {
    None,          // the scan is usable
    NoBeams,       // fewer than kMinScanBeams beams
    TooManyBeams,  // more than kMaxScanBeams beams
    BadAperture,   // aperture not finite, <= 0 or > kMaxScanAperture
};
constexpr std::size_t kScanSkipReasons = 4;  // including None

/// "ok", "no_beams", "too_many_beams", "bad_aperture".
inline const char* toString(ScanSkipReason r) {
    switch (r) {
        case ScanSkipReason::None:
            return "ok";
        case ScanSkipReason::NoBeams:
            return "no_beams";
        case ScanSkipReason::TooManyBeams:
            return "too_many_beams";
        case ScanSkipReason::BadAperture:
            return "bad_aperture";
    }
    return "unknown";
}

/// The reason in words, for messages: "fewer than 2 beams", "more than 65536 beams", "an
/// aperture that is not finite, <= 0 or above 2 pi" ("" for None).
inline const char* describe(ScanSkipReason r) {
    switch (r) {
        case ScanSkipReason::None:
            return "";
        case ScanSkipReason::NoBeams:
            return "fewer than 2 beams";
        case ScanSkipReason::TooManyBeams:
            return "more than 65536 beams";
        case ScanSkipReason::BadAperture:
            return "an aperture that is not finite, <= 0 or above 2 pi";
    }
    return "";
}

/// Checks beam count and aperture against the limits above.
inline ScanSkipReason checkGeometry(const ScanGeometry& g) {
    if (g.beams < kMinScanBeams) return ScanSkipReason::NoBeams;
    if (g.beams > kMaxScanBeams) return ScanSkipReason::TooManyBeams;
    if (!(g.aperture > 0.0) || !(g.aperture <= kMaxScanAperture))
        return ScanSkipReason::BadAperture;
    return ScanSkipReason::None;
}

/// A range the adapter keeps as a measurement: finite, >= 0 and <= kMaxScanRangeM.
inline bool isUsableRange(float r) { return r >= 0.0f && r <= kMaxScanRangeM; }

/// One scan as the core sees it. `valid[i] != 0` means beam i holds a usable range.
/// Stages never delete beams: removing a point clears its valid flag. The one exception is
/// beam_count (kfd/filters/beam_count.h), which resamples the whole scan to a fixed count.
struct Scan {
    ScanGeometry geometry;
    std::vector<float> range;         // m, one per beam
    std::vector<std::uint8_t> valid;  // 1 = usable, 0 = invalid or removed
    std::vector<float> intensity;     // one per beam (the driver's units), or empty: none
    double timestamp = std::numeric_limits<double>::quiet_NaN();  // s (any epoch), NaN = unknown
    std::optional<Pose2D> odometry;  // absolute odometry at the scan, when known
    Pose2D sensor_pose;              // the sensor on the robot (MRPT's sensorPose), m and rad
    /// The sensor's own maximum range (m; MRPT's maxRange, a LaserScan's range_max): Algorithm
    /// 1's default upper limit. +inf when the source does not say.
    float max_range = std::numeric_limits<float>::infinity();

    std::size_t size() const { return range.size(); }
    /// Beams whose valid flag is set (vectorised: a few hundred instructions for 1081 beams).
    std::size_t countValid() const { return countNonZero(valid.data(), valid.size()); }

    /// How many of the n bytes at p are not 0.
    static std::size_t countNonZero(const std::uint8_t* p, std::size_t n);
    /// The first index from i on, below n, whose byte at p is not 0; n when there is none.
    /// Eight bytes at a time: for sparse flags (a few beams of a scan).
    static std::size_t nextNonZero(const std::uint8_t* p, std::size_t i, std::size_t n);
};

}  // namespace kfd
