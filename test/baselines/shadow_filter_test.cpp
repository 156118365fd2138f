// The shadow filter baseline (laser_filters' ScanShadowsFilter test) on hand-made scans, and
// against a plain reference over random scans.
#include "kfd/baselines/shadow_filter.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

using test::deg2rad;

TEST(ShadowFilter, AVeilingPointBetweenTwoSurfacesIsRemoved) {
    // A box edge at 2 m in front of a wall at 5 m; beam 100 returns between them.
    Scan s = test::flatWall(181, deg2rad(90.0), 5.0);
    test::setRange(s, 60, 99, 2.0);
    test::insertSpike(s, 100, 3.5);
    ShadowFilter::Params p;
    p.neighbors = 1;  // laser_filters removes the farther neighbours of a shadow point only
    const auto r = ShadowFilter(p).filter(s);
    EXPECT_GE(r.shadow_tests, 1u);
    EXPECT_EQ(s.valid[100], 0);  // farther than the box edge it shadows
    EXPECT_EQ(s.valid[99], 1);   // the box itself stays
}

TEST(ShadowFilter, TheStartPointGoesTooWhenAsked) {
    Scan s = test::flatWall(181, deg2rad(90.0), 5.0);
    test::setRange(s, 60, 99, 2.0);
    test::insertSpike(s, 100, 3.5);
    ShadowFilter::Params p;
    p.neighbors = 1;
    p.remove_start = true;
    ShadowFilter(p).filter(s);
    EXPECT_EQ(s.valid[100], 0);
    EXPECT_EQ(s.valid[99], 0);  // the box edge whose test failed against the veiling point
    EXPECT_EQ(s.valid[98], 1);
}

TEST(ShadowFilter, ASurfaceFacingTheSensorIsKept) {
    Scan s = test::flatWall(181, deg2rad(60.0), 3.0);
    const auto r = ShadowFilter().filter(s);
    EXPECT_EQ(r.points_removed, 0u);
}

TEST(ShadowFilter, NeighboursFartherThanTheShadowedPointGoToo) {
    Scan s = test::flatWall(181, deg2rad(90.0), 5.0);
    test::setRange(s, 60, 99, 2.0);
    ShadowFilter::Params p;
    p.neighbors = 3;
    ShadowFilter(p).filter(s);
    // The box edge at beam 99 and the wall's first beam 100 see each other along their rays:
    // the wall's beams within 3 of them that are farther go (100..103), the box stays.
    for (std::size_t i = 100; i <= 103; ++i) EXPECT_EQ(s.valid[i], 0) << i;
    EXPECT_EQ(s.valid[104], 1);
    for (std::size_t i = 60; i <= 99; ++i) EXPECT_EQ(s.valid[i], 1) << i;
}

// The filter as laser_filters states it, written plainly (every pair, a set of indices).
std::vector<std::uint8_t> plainShadows(const Scan& s, const ShadowFilter::Params& p) {
    const std::size_t n = s.size();
    std::vector<std::uint8_t> out = s.valid;
    const double res = s.geometry.resolution();
    for (std::size_t i = 0; i < n; ++i) {
        if (!s.valid[i]) continue;
        for (long y = -static_cast<long>(p.window); y <= static_cast<long>(p.window); ++y) {
            const long j = static_cast<long>(i) + y;
            if (j < 0 || j >= static_cast<long>(n) || y == 0 || !s.valid[j]) continue;
            const double angle =
                std::abs(std::atan2(s.range[j] * std::sin(std::abs(y) * res),
                                    s.range[i] - s.range[j] * std::cos(std::abs(y) * res))) *
                180.0 / kPi;
            if (angle >= p.min_angle_deg && angle <= p.max_angle_deg) continue;
            for (long k = static_cast<long>(i) - static_cast<long>(p.neighbors);
                 k <= static_cast<long>(i + p.neighbors); ++k)
                if (k >= 0 && k < static_cast<long>(n) && s.valid[k] && s.range[i] < s.range[k])
                    out[k] = 0;
            if (p.remove_start) out[i] = 0;
        }
    }
    return out;
}

TEST(ShadowFilter, MatchesAPlainReferenceOnRandomScans) {
    std::mt19937 rng(11);
    for (int k = 0; k < 200; ++k) {
        Scan s = test::randomScan(rng, 50 + rng() % 300, kPi);
        ShadowFilter::Params p;
        p.window = 1 + rng() % 3;
        p.neighbors = rng() % 25;
        p.remove_start = rng() % 2;
        const auto expect = plainShadows(s, p);
        ShadowFilter(p).filter(s);
        EXPECT_EQ(s.valid, expect) << k;
    }
}

TEST(ShadowFilter, BadParametersAreRejected) {
    auto bad = [](auto change) {
        ShadowFilter::Params p;
        change(p);
        EXPECT_THROW(ShadowFilter{p}, ParameterError);
    };
    bad([](auto& p) { p.min_angle_deg = 20.0, p.max_angle_deg = 10.0; });
    bad([](auto& p) { p.max_angle_deg = 190.0; });
    bad([](auto& p) { p.min_angle_deg = -1.0; });
    bad([](auto& p) { p.window = 0; });
    bad([](auto& p) { p.neighbors = 1001; });
}

}  // namespace
}  // namespace kfd
