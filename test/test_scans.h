// Tiny hand-made scans shared by the core unit tests (std only).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "kfd/paper/clusters.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {
namespace test {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

inline double deg2rad(double deg) { return deg * kPi / 180.0; }

/// A valid-flag vector written inline: flags({1, 0, 1}).
inline std::vector<std::uint8_t> flags(std::initializer_list<int> v) {
    return std::vector<std::uint8_t>(v.begin(), v.end());
}

/// The kfd::Error text a Filter's constructor gives for `p`, or "<no error>".
template <class Filter>
std::string constructionError(const typename Filter::Params& p) {
    try {
        Filter f(p);
    } catch (const kfd::Error& e) {
        return e.what();
    }
    return "<no error>";
}

/// Geometry of `beams` beams over `aperture` rad (MRPT convention, see ScanGeometry).
inline ScanGeometry geometry(std::size_t beams, double aperture, bool right_to_left = true) {
    ScanGeometry g;
    g.beams = beams;
    g.aperture = aperture;
    g.right_to_left = right_to_left;
    return g;
}

/// Aperture of a 360-degree scanner whose last beam stops one step short of the first one:
/// 2*pi*(N-1)/N, so the seam gap equals the angular resolution (2*pi/N).
inline double fullCircleAperture(std::size_t beams) {
    return 2.0 * kPi * static_cast<double>(beams - 1) / static_cast<double>(beams);
}

/// A scan with the given ranges, every beam valid.
inline Scan makeScan(const std::vector<float>& ranges, double aperture = kPi,
                     bool right_to_left = true) {
    Scan s;
    s.geometry = geometry(ranges.size(), aperture, right_to_left);
    s.range = ranges;
    s.valid.assign(ranges.size(), 1);
    return s;
}

/// Every beam at the same range r: an arc of radius r (a circle when the aperture closes it).
inline Scan arc(std::size_t beams, double aperture, double r) {
    return makeScan(std::vector<float>(beams, static_cast<float>(r)), aperture);
}

/// A 360-degree scanner (aperture 2*pi*(N-1)/N) inside a round room of radius r.
inline Scan circle(std::size_t beams, double r) { return arc(beams, fullCircleAperture(beams), r); }

/// A flat wall perpendicular to the forward axis at distance d (m): r_i = d / cos(angle_i).
/// Needs aperture < pi.
inline Scan flatWall(std::size_t beams, double aperture, double d) {
    Scan s = arc(beams, aperture, d);
    for (std::size_t i = 0; i < beams; ++i)
        s.range[i] = static_cast<float>(d / std::cos(s.geometry.angle(i)));
    return s;
}

/// A scan whose beams all point straight ahead (aperture 0): beam i is the point (range_i, 0)
/// exactly, so distances between points (and their means) are exact differences of ranges.
inline Scan line(const std::vector<float>& ranges) { return makeScan(ranges, 0.0); }

/// A scan in which no beam returned anything (all invalid, ranges 0): draw on it with setRange.
inline Scan emptyScan(std::size_t beams, double aperture) {
    Scan s = arc(beams, aperture, 0.0);
    s.valid.assign(beams, 0);
    return s;
}

/// Sets beams [first, last] (inclusive) to range r and marks them valid.
inline void setRange(Scan& s, std::size_t first, std::size_t last, double r) {
    for (std::size_t i = first; i <= last; ++i) {
        s.range[i] = static_cast<float>(r);
        s.valid[i] = 1;
    }
}

/// Beams [first, last] (inclusive) see a flat wall perpendicular to the forward axis at
/// distance d (m): r_i = d / cos(angle_i). Those beams must point less than 90 deg off forward.
inline void setWall(Scan& s, std::size_t first, std::size_t last, double d) {
    for (std::size_t i = first; i <= last; ++i) {
        s.range[i] = static_cast<float>(d / std::cos(s.geometry.angle(i)));
        s.valid[i] = 1;
    }
}

/// A one-beam spike: beam i returns range r (e.g. in front of a wall).
inline void insertSpike(Scan& s, std::size_t i, double r) { setRange(s, i, i, r); }

/// Isolated outliers: each listed beam returns range r.
inline void insertOutliers(Scan& s, std::initializer_list<std::size_t> beams, double r) {
    for (const auto i : beams) insertSpike(s, i, r);
}

/// Clears the valid flag of beams [first, last] (inclusive); ranges are left untouched.
inline void invalidate(Scan& s, std::size_t first, std::size_t last) {
    for (std::size_t i = first; i <= last; ++i) s.valid[i] = 0;
}

/// A wall of a hand-made world, from (x0, y0) to (x1, y1) (m).
struct Segment {
    double x0, y0, x1, y1;
};

/// A scan taken at `pose` in a world of segments (ray casting; no return beyond 30 m), with
/// `pose` as its odometry.
inline Scan castScan(const std::vector<Segment>& world, const Pose2D& pose, std::size_t beams = 361,
                     double aperture = kPi) {
    Scan s = emptyScan(beams, aperture);
    for (std::size_t i = 0; i < beams; ++i) {
        const double a = pose.phi + s.geometry.angle(i);
        const double dx = std::cos(a), dy = std::sin(a);
        double best = 30.0;
        for (const auto& w : world) {
            const double ex = w.x1 - w.x0, ey = w.y1 - w.y0;
            const double den = dx * ey - dy * ex;
            if (std::abs(den) < 1e-12) continue;
            const double t = ((w.x0 - pose.x) * ey - (w.y0 - pose.y) * ex) / den;
            const double u = ((w.x0 - pose.x) * dy - (w.y0 - pose.y) * dx) / den;
            if (t > 1e-6 && u >= 0.0 && u <= 1.0) best = std::min(best, t);
        }
        if (best < 30.0) {
            s.range[i] = static_cast<float>(best);
            s.valid[i] = 1;
        }
    }
    s.odometry = pose;
    return s;
}

/// A wall at 3 m over 90 degrees (181 beams, see flatWall) with isolated outliers: beams 20 and
/// 150 at 8 m (behind the wall) and beam 90 at 1 m (in front of it).
inline Scan wallWithOutliers() {
    Scan s = flatWall(181, deg2rad(90.0), 3.0);
    insertOutliers(s, {20, 150}, 8.0);
    insertSpike(s, 90, 1.0);
    return s;
}

/// A wall 4 m ahead over -60..60 deg (181 beams over 180 deg) with isolated outliers at 1 m on
/// beams 50, 100 and 130, an out-of-range beam (60, 45 m, beyond the sensor's 30 m maximum)
/// and a NaN beam (61), stamped 100 s and without odometry.
inline Scan noisyWall() {
    Scan scan = emptyScan(181, kPi);
    scan.max_range = 30.0f;
    setWall(scan, 30, 150, 4.0);
    insertOutliers(scan, {50, 100, 130}, 1.0);
    scan.range[60] = 45.0f;
    scan.range[61] = std::numeric_limits<float>::quiet_NaN();
    scan.timestamp = 100.0;
    return scan;
}

/// A 360-degree scan (aperture `aperture`) with one object at 3 m across the seam (the last
/// ten and the first ten beams) and another at 3 m on beams 100-150.
inline Scan seamObjectScan(std::size_t beams, double aperture) {
    Scan scan = emptyScan(beams, aperture);
    setRange(scan, beams - 10, beams - 1, 3.0);
    setRange(scan, 0, 9, 3.0);
    setRange(scan, 100, 150, 3.0);
    return scan;
}

/// A 360-degree scanner (see fullCircleAperture) seeing two objects at 3 m on either side of
/// the seam, beams N-20..N-7 and 6..20: 13 beams apart across the seam.
inline Scan seamGapScan(std::size_t beams) {
    Scan scan = emptyScan(beams, fullCircleAperture(beams));
    setRange(scan, beams - 20, beams - 7, 3.0);
    setRange(scan, 6, 20, 3.0);
    return scan;
}

/// True when beams a and b are in the same cluster (noise is in none).
inline bool sameCluster(const Clusters& c, std::size_t a, std::size_t b) {
    return c.label[a] >= 0 && c.label[a] == c.label[b];
}

/// Random scan made of pieces: runs of invalid beams, smooth surfaces (linear in range),
/// noisy surfaces and one-beam spikes, ranges in [0.2, 12] m. Deterministic for a seeded rng.
inline Scan randomScan(std::mt19937& rng, std::size_t beams, double aperture) {
    Scan s = arc(beams, aperture, 1.0);
    std::uniform_real_distribution<double> range(0.2, 12.0);
    std::uniform_real_distribution<double> slope(-0.15, 0.15);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_int_distribution<std::size_t> len(1, 25);
    std::size_t i = 0;
    while (i < beams) {
        const std::size_t n = std::min(len(rng), beams - i);
        const double kind = unit(rng);
        double r = range(rng);
        const double dr = slope(rng);
        for (std::size_t k = i; k < i + n; ++k) {
            if (kind < 0.2) {  // nothing returned
                s.valid[k] = 0;
                s.range[k] = static_cast<float>(range(rng));
            } else if (kind < 0.3) {  // scattered points
                s.range[k] = static_cast<float>(range(rng));
            } else {  // a surface, with the odd spike
                r = std::clamp(r + dr, 0.2, 12.0);
                s.range[k] = static_cast<float>(unit(rng) < 0.05 ? range(rng) : r);
            }
        }
        i += n;
    }
    return s;
}

/// One of the apertures the random comparisons use (90, 180 or 270 deg, or a full circle of
/// `beams` beams), drawn from rng.
inline double randomAperture(std::mt19937& rng, std::size_t beams) {
    const double apertures[] = {deg2rad(90.0), kPi, deg2rad(270.0), fullCircleAperture(beams)};
    return apertures[std::uniform_int_distribution<int>(0, 3)(rng)];
}

/// Two random scans drawn one after the other from an rng seeded 11: a large 360-degree one
/// (720 beams) and a small 180-degree one (90 beams). For the tests that a filter run on the
/// large scan leaves nothing behind for the small one.
struct LargeThenSmall {
    Scan large, small;
};
inline LargeThenSmall largeThenSmallScans() {
    std::mt19937 rng(11);
    LargeThenSmall s;
    s.large = randomScan(rng, 720, fullCircleAperture(720));
    s.small = randomScan(rng, 90, deg2rad(180.0));
    return s;
}

/// Makes two beams valid without a position: beam N/3 NaN and beam N/2 +inf.
inline void addBeamsWithoutPosition(Scan& s) {
    s.range[s.size() / 3] = std::numeric_limits<float>::quiet_NaN();
    s.valid[s.size() / 3] = 1;
    s.range[s.size() / 2] = std::numeric_limits<float>::infinity();
    s.valid[s.size() / 2] = 1;
}

/// The valid beams with a finite range as Cartesian points, converted as the baseline filters
/// do (double trigonometry, then float), so that distances compare identically.
struct Points {
    std::vector<float> x, y;
    std::vector<std::size_t> beam;
    std::size_t size() const { return x.size(); }
};

inline Points cartesian(const Scan& s) {
    Points p;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (!s.valid[i] || !std::isfinite(s.range[i])) continue;
        const double a = s.geometry.angle(i);
        p.x.push_back(static_cast<float>(s.range[i] * std::cos(a)));
        p.y.push_back(static_cast<float>(s.range[i] * std::sin(a)));
        p.beam.push_back(i);
    }
    return p;
}

/// The valid flags once the valid beams without a finite range (no position) are removed.
inline std::vector<std::uint8_t> withPosition(const Scan& s) {
    std::vector<std::uint8_t> v = s.valid;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (!std::isfinite(s.range[i])) v[i] = 0;
    return v;
}

/// Squared distances (float) from point i to every other point, in index order.
inline std::vector<float> squaredDistancesFrom(const Points& p, std::size_t i) {
    std::vector<float> d2;
    for (std::size_t j = 0; j < p.size(); ++j) {
        if (j == i) continue;
        const float dx = p.x[j] - p.x[i], dy = p.y[j] - p.y[i];
        d2.push_back(dx * dx + dy * dy);
    }
    return d2;
}

/// True when two labellings (-1 = none) describe the same partition, whatever the label values.
inline bool samePartition(const std::vector<std::int32_t>& a, const std::vector<std::int32_t>& b) {
    if (a.size() != b.size()) return false;
    std::map<std::int32_t, std::int32_t> ab, ba;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if ((a[i] < 0) != (b[i] < 0)) return false;
        if (a[i] < 0) continue;
        const auto x = ab.emplace(a[i], b[i]).first;
        const auto y = ba.emplace(b[i], a[i]).first;
        if (x->second != b[i] || y->second != a[i]) return false;
    }
    return true;
}

/// Number of distinct labels >= 0 among the given beams.
inline std::size_t distinctLabels(const std::vector<std::int32_t>& label, std::size_t first,
                                  std::size_t last) {
    std::vector<std::int32_t> seen;
    for (std::size_t i = first; i <= last; ++i)
        if (label[i] >= 0 && std::find(seen.begin(), seen.end(), label[i]) == seen.end())
            seen.push_back(label[i]);
    return seen.size();
}

}  // namespace test
}  // namespace kfd
