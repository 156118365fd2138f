// Tiny hand-made scans shared by the core unit tests (std only).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "kfd/core/error.h"
#include "kfd/core/scan.h"

namespace kfd {
namespace test {

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
