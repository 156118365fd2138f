// The speckle filter baseline (laser_filters' LaserScanSpeckleFilter, distance and radius tests)
// on hand-made scans, and against a plain reference over random scans.
#include "kfd/baselines/speckle_filter.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

using test::deg2rad;

TEST(SpeckleFilter, AnIsolatedSpikeInFrontOfAWallIsRemoved) {
    Scan s = test::flatWall(181, deg2rad(90.0), 3.0);
    test::insertSpike(s, 90, 1.0);
    const auto r = SpeckleFilter().filter(s);
    EXPECT_EQ(s.valid[90], 0);
    EXPECT_EQ(r.points_removed, 1u);
}

TEST(SpeckleFilter, TwoAgreeingBeamsAreKept) {
    // A burst of two beams agreeing within 0.3 m is a run of window 2: speckle cannot see it.
    Scan s = test::flatWall(181, deg2rad(90.0), 3.0);
    test::setRange(s, 90, 91, 1.0);
    EXPECT_EQ(SpeckleFilter().filter(s).points_removed, 0u);
}

TEST(SpeckleFilter, BeamsBeyondMaxRangeAreNeverRemoved) {
    Scan s = test::flatWall(181, deg2rad(90.0), 3.0);
    test::insertSpike(s, 90, 1.0);
    SpeckleFilter::Params p;
    p.max_range = 0.5;
    EXPECT_EQ(SpeckleFilter(p).filter(s).points_removed, 0u);
}

TEST(SpeckleFilter, TheRadiusTestCountsNeighboursWithinTheDistance) {
    Scan s = test::flatWall(181, deg2rad(90.0), 3.0);  // beams 0.5 deg apart: 2.6 cm at 3 m
    test::insertSpike(s, 90, 2.0);
    SpeckleFilter::Params p;
    p.radius = true;
    p.max_range_difference = 0.1;
    p.window = 1;
    SpeckleFilter(p).filter(s);
    EXPECT_EQ(s.valid[90], 0);
    EXPECT_EQ(s.valid[89], 1);
    EXPECT_EQ(s.valid[91], 1);
    // With window 2 the run starting at beam 89 passes on 89's own neighbours and keeps beam
    // 90 with it: laser_filters' radius test marks the whole run from its first beam.
    Scan t = test::flatWall(181, deg2rad(90.0), 3.0);
    test::insertSpike(t, 90, 2.0);
    p.window = 2;
    SpeckleFilter(p).filter(t);
    EXPECT_EQ(t.valid[90], 1);
}

TEST(SpeckleFilter, AScanOfAtMostWindowPlusOneBeamsIsLeftAlone) {
    Scan s = test::line({1.0f, 5.0f, 1.0f});
    EXPECT_EQ(SpeckleFilter().filter(s).points_removed, 0u);
}

// The filter as laser_filters states it, written plainly (a window at every start, NaN for an
// invalid beam).
std::vector<std::uint8_t> plainSpeckle(const Scan& s, const SpeckleFilter::Params& p) {
    const std::size_t n = s.size(), w = p.window;
    if (n <= w + 1) return s.valid;
    std::vector<double> r(n);
    for (std::size_t i = 0; i < n; ++i) r[i] = s.valid[i] ? s.range[i] : std::nan("");
    std::vector<bool> valid(n);
    for (std::size_t i = 0; i < n; ++i) valid[i] = r[i] > p.max_range;
    for (std::size_t idx = 0; idx < n - w + 1; ++idx) {
        bool ok = !std::isnan(r[idx]);
        if (!p.radius) {
            for (std::size_t k = 1; k < w && ok; ++k)
                if (idx + k < n && (std::isnan(r[idx + k]) ||
                                    std::fabs(r[idx + k] - r[idx]) > p.max_range_difference))
                    ok = false;
        } else if (ok) {
            int found = 0;
            for (int y = -static_cast<int>(w);
                 y <= static_cast<int>(w) && found < static_cast<int>(w); ++y) {
                const long j = static_cast<long>(idx) + y;
                if (j < 0 || j >= static_cast<long>(n) || y == 0 || std::isnan(r[j])) continue;
                const double a = y * s.geometry.resolution();
                const double d = std::sqrt(
                    std::max(0.0, r[idx] * r[idx] + r[j] * r[j] - 2 * r[idx] * r[j] * std::cos(a)));
                if (d <= p.max_range_difference) ++found;
            }
            ok = found >= static_cast<int>(w);
        }
        for (std::size_t k = 0; k < w; ++k)
            if (idx + k < n) valid[idx + k] = valid[idx + k] || ok;
    }
    std::vector<std::uint8_t> out = s.valid;
    for (std::size_t i = 0; i < n; ++i)
        if (!valid[i]) out[i] = 0;
    return out;
}

TEST(SpeckleFilter, MatchesAPlainReferenceOnRandomScans) {
    std::mt19937 rng(12);
    for (int k = 0; k < 300; ++k) {
        Scan s = test::randomScan(rng, 3 + rng() % 300, kPi);
        SpeckleFilter::Params p;
        p.radius = rng() % 2;
        p.window = 1 + rng() % 5;
        p.max_range_difference = 0.05 + 0.5 * (rng() % 100) / 100.0;
        p.max_range = rng() % 3 == 0 ? 5.0 : 80.0;
        const auto expect = plainSpeckle(s, p);
        SpeckleFilter(p).filter(s);
        EXPECT_EQ(s.valid, expect) << k;
    }
}

TEST(SpeckleFilter, BadParametersAreRejected) {
    auto bad = [](auto change) {
        SpeckleFilter::Params p;
        change(p);
        EXPECT_THROW(SpeckleFilter{p}, ParameterError);
    };
    bad([](auto& p) { p.window = 0; });
    bad([](auto& p) { p.window = 101; });
    bad([](auto& p) { p.max_range = -1.0; });
    bad([](auto& p) { p.max_range_difference = std::nan(""); });
}

}  // namespace
}  // namespace kfd
