#include "kfd/paper/rings.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

using test::makeScan;

RingPartition makeRings(std::size_t t, double r_max = 0.0) {
    RingPartition::Params p;
    p.rings = t;
    p.r_max = r_max;
    return RingPartition(p);
}

constexpr std::uint8_t kNo = RingPartition::kNoRing;

TEST(RingPartition, OuterRadiusFormula) {
    // r_i = sqrt(i) * r_max / sqrt(t) (Formula 8); t = 5, r_max = 10.
    const auto rp = makeRings(5);
    EXPECT_NEAR(rp.outerRadius(1, 10.0), 4.47213595499958, 1e-12);   // sqrt(20)
    EXPECT_NEAR(rp.outerRadius(2, 10.0), 6.324555320336759, 1e-12);  // sqrt(40)
    EXPECT_NEAR(rp.outerRadius(4, 10.0), 8.94427190999916, 1e-12);   // sqrt(80)
    EXPECT_DOUBLE_EQ(rp.outerRadius(5, 10.0), 10.0);
    EXPECT_DOUBLE_EQ(rp.outerRadius(0, 10.0), 0.0);
}

TEST(RingPartition, RingsHaveEqualAreas) {
    for (const std::size_t t : {1u, 2u, 5u, 7u, 12u}) {
        const auto rp = makeRings(t);
        const double r_max = 23.5;
        const double area = kPi * r_max * r_max / static_cast<double>(t);
        for (std::size_t i = 1; i <= t; ++i) {
            const double ro = rp.outerRadius(i, r_max), ri = rp.outerRadius(i - 1, r_max);
            EXPECT_NEAR(kPi * (ro * ro - ri * ri), area, 1e-9) << "t " << t << " ring " << i;
        }
    }
}

TEST(RingPartition, PointOnOuterRadiusBelongsToThatRing) {
    // t = 16, r_max = 4: r_i = sqrt(i), exact for i = 1, 4, 9, 16. Ring i spans (r_{i-1}, r_i].
    const auto rp = makeRings(16);
    EXPECT_EQ(rp.ringOf(1.0, 4.0), 0u);
    EXPECT_EQ(rp.ringOf(2.0, 4.0), 3u);
    EXPECT_EQ(rp.ringOf(3.0, 4.0), 8u);
    EXPECT_EQ(rp.ringOf(4.0, 4.0), 15u);
    // Just outside a boundary is the next ring.
    EXPECT_EQ(rp.ringOf(1.0 + 1e-9, 4.0), 1u);
    EXPECT_EQ(rp.ringOf(2.0 + 1e-9, 4.0), 4u);
    EXPECT_EQ(rp.ringOf(3.0 + 1e-9, 4.0), 9u);
    // t = 4, r_max = 4: r_1 = 2.
    const auto four = makeRings(4);
    EXPECT_EQ(four.ringOf(2.0, 4.0), 0u);
    EXPECT_EQ(four.ringOf(2.001, 4.0), 1u);
}

TEST(RingPartition, RingOfAroundEveryBoundary) {
    const auto rp = makeRings(5);
    const double r_max = 10.0;
    for (std::size_t i = 1; i <= 5; ++i) {
        const double r = rp.outerRadius(i, r_max);
        EXPECT_EQ(rp.ringOf(r * (1.0 - 1e-9), r_max), i - 1) << i;
        if (i < 5) {
            EXPECT_EQ(rp.ringOf(r * (1.0 + 1e-9), r_max), i) << i;
        }
    }
    EXPECT_EQ(rp.ringOf(1.0, r_max), 0u);
    EXPECT_EQ(rp.ringOf(5.0, r_max), 1u);
    EXPECT_EQ(rp.ringOf(7.0, r_max), 2u);
    EXPECT_EQ(rp.ringOf(8.5, r_max), 3u);
    EXPECT_EQ(rp.ringOf(9.5, r_max), 4u);
}

TEST(RingPartition, ZeroRangeIsInTheFirstRing) { EXPECT_EQ(makeRings(5).ringOf(0.0, 10.0), 0u); }

TEST(RingPartition, BeyondRMaxIsTheLastRing) { EXPECT_EQ(makeRings(5).ringOf(50.0, 10.0), 4u); }

TEST(RingPartition, AutomaticRMaxIsTheFarthestValidPoint) {
    Scan scan = makeScan({1.0f, 2.0f, 10.0f, 4.0f, std::numeric_limits<float>::quiet_NaN()});
    scan.valid[2] = 0;  // the farthest return is invalid and must not count
    scan.valid[4] = 0;
    std::vector<std::uint8_t> ring;
    // t = 4 around r_max = 4: boundaries 2, 2.83, 3.46, 4.
    const double r_max = makeRings(4).compute(scan, ring);
    EXPECT_DOUBLE_EQ(r_max, 4.0);
    EXPECT_EQ(ring, (std::vector<std::uint8_t>{0, 0, kNo, 3, kNo}));
}

TEST(RingPartition, FixedRMaxClampsFartherPointsIntoTheLastRing) {
    const Scan scan = makeScan({1.0f, 12.0f, 5.0f, 3.0f});
    std::vector<std::uint8_t> ring;
    // t = 5, r_max = 5: boundaries 2.24, 3.16, 3.87, 4.47, 5.
    const double r_max = makeRings(5, 5.0).compute(scan, ring);
    EXPECT_DOUBLE_EQ(r_max, 5.0);
    EXPECT_EQ(ring, (std::vector<std::uint8_t>{0, 4, 4, 1}));
}

TEST(RingPartition, InvalidBeamsHaveNoRing) {
    Scan scan = makeScan({1.0f, 2.0f, 3.0f});
    scan.valid = {0, 1, 0};
    std::vector<std::uint8_t> ring(10, 7);
    makeRings(3).compute(scan, ring);
    EXPECT_EQ(ring, (std::vector<std::uint8_t>{kNo, 2, kNo}));
}

TEST(RingPartition, AllInvalidScan) {
    Scan scan = makeScan({1.0f, 2.0f, 3.0f});
    scan.valid.assign(3, 0);
    std::vector<std::uint8_t> ring;
    EXPECT_EQ(makeRings(5).compute(scan, ring), 0.0);
    EXPECT_EQ(ring, (std::vector<std::uint8_t>{kNo, kNo, kNo}));
}

TEST(RingPartition, SingleRingHoldsEverything) {
    const Scan scan = makeScan({0.5f, 3.0f, 9.0f});
    std::vector<std::uint8_t> ring;
    makeRings(1).compute(scan, ring);
    EXPECT_EQ(ring, (std::vector<std::uint8_t>{0, 0, 0}));
}

TEST(RingPartition, UniformDiscFillsRingsEqually) {
    // Points spread uniformly over the disc (r = r_max * sqrt(u)) fall about equally often in
    // every ring: the point of equal areas.
    const auto rp = makeRings(5);
    std::vector<std::size_t> count(5, 0);
    const std::size_t n = 10000;
    for (std::size_t k = 0; k < n; ++k) {
        const double u = (static_cast<double>(k) + 0.5) / static_cast<double>(n);
        ++count[rp.ringOf(10.0 * std::sqrt(u), 10.0)];
    }
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(count[i], n / 5) << i;
}

TEST(RingPartition, RejectsBadParams) {
    RingPartition rp;
    EXPECT_THROW(rp.initialize({0, 0.0}), kfd::ParameterError);
    EXPECT_THROW(rp.initialize({256, 0.0}), kfd::ParameterError);
    EXPECT_THROW(rp.initialize({5, -1.0}), kfd::ParameterError);
    EXPECT_THROW(rp.initialize({5, std::numeric_limits<double>::quiet_NaN()}), kfd::ParameterError);
    EXPECT_THROW(rp.initialize({5, std::numeric_limits<double>::infinity()}), kfd::ParameterError);
    EXPECT_NO_THROW(rp.initialize({254, 12.0}));
    EXPECT_EQ(rp.params().rings, 254u);
    EXPECT_DOUBLE_EQ(rp.params().r_max, 12.0);
}

TEST(RingPartition, ManyRingsNeverCollideWithNoRing) {
    RingPartition rp({254, 0.0});
    const Scan scan = makeScan({1.0f, 100.0f});
    std::vector<std::uint8_t> ring;
    rp.compute(scan, ring);
    EXPECT_EQ(ring[1], 253u);
    EXPECT_NE(ring[1], kNo);
}

}  // namespace
}  // namespace kfd
