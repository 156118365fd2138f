#include "kfd/paper/distance_filter.h"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

using test::makeScan;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

DistanceFilter makeFilter(double min_range, double max_range) {
    DistanceFilter::Params p;
    p.min_range = min_range;
    p.max_range = max_range;
    return DistanceFilter(p);
}

TEST(DistanceFilter, KeepsRangesInsideTheInterval) {
    Scan scan = makeScan({0.5f, 1.0f, 2.25f, 4.0f});
    const auto res = makeFilter(0.5, 4.0).filter(scan);
    // Both ends of [min_range, max_range] are usable (Algorithm 1 uses <=).
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 1, 1, 1}));
    EXPECT_EQ(res.valid_in, 4u);
    EXPECT_EQ(res.valid_out, 4u);
    EXPECT_EQ(res.removed_out_of_range, 0u);
    EXPECT_EQ(res.removed_non_finite, 0u);
}

TEST(DistanceFilter, RemovesOutOfRange) {
    Scan scan = makeScan({0.25f, 0.5f, 3.0f, 4.0f, 4.5f, 0.0f, -1.0f});
    const auto res = makeFilter(0.5, 4.0).filter(scan);
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{0, 1, 1, 1, 0, 0, 0}));
    EXPECT_EQ(res.valid_in, 7u);
    EXPECT_EQ(res.removed_out_of_range, 4u);
    EXPECT_EQ(res.removed_non_finite, 0u);
    EXPECT_EQ(res.valid_out, 3u);
}

TEST(DistanceFilter, RemovesNaNAndInfinity) {
    Scan scan = makeScan({1.0f, kNaN, kInf, -kInf, 2.0f});
    const auto res = makeFilter(0.1, 30.0).filter(scan);
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 0, 0, 0, 1}));
    EXPECT_EQ(res.valid_in, 5u);
    EXPECT_EQ(res.removed_non_finite, 3u);
    EXPECT_EQ(res.removed_out_of_range, 0u);
    EXPECT_EQ(res.valid_out, 2u);
}

TEST(DistanceFilter, AlreadyInvalidBeamsAreNotCounted) {
    // Beams the driver already flagged stay invalid, whatever their range, and are not counted
    // as removed by Algorithm 1.
    Scan scan = makeScan({1.0f, kNaN, 50.0f, 1.0f, 0.01f, 2.0f});
    scan.valid = {0, 0, 0, 0, 1, 1};
    const auto res = makeFilter(0.1, 30.0).filter(scan);
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{0, 0, 0, 0, 0, 1}));
    EXPECT_EQ(res.valid_in, 2u);
    EXPECT_EQ(res.removed_non_finite, 0u);
    EXPECT_EQ(res.removed_out_of_range, 1u);
    EXPECT_EQ(res.valid_out, 1u);
}

TEST(DistanceFilter, CountsAddUp) {
    Scan scan = makeScan({kNaN, 0.05f, 1.0f, 40.0f, kInf, 3.0f, 29.0f, 31.0f});
    scan.valid[2] = 0;
    const auto res = makeFilter(0.1, 30.0).filter(scan);
    EXPECT_EQ(res.valid_in, 7u);
    EXPECT_EQ(res.removed_non_finite, 2u);
    EXPECT_EQ(res.removed_out_of_range, 3u);
    EXPECT_EQ(res.valid_out, 2u);
    EXPECT_EQ(res.valid_out, scan.countValid());
}

TEST(DistanceFilter, PreservesBeamCountAndRanges) {
    const std::vector<float> ranges{0.05f, 1.0f, kNaN, 35.0f, kInf, 2.5f};
    Scan scan = makeScan(ranges);
    makeFilter(0.1, 30.0).filter(scan);
    ASSERT_EQ(scan.size(), ranges.size());
    ASSERT_EQ(scan.valid.size(), ranges.size());
    EXPECT_EQ(scan.geometry.beams, ranges.size());
    for (std::size_t i = 0; i < ranges.size(); ++i) {
        if (std::isnan(ranges[i]))
            EXPECT_TRUE(std::isnan(scan.range[i])) << i;
        else
            EXPECT_EQ(scan.range[i], ranges[i]) << i;
    }
}

TEST(DistanceFilter, FilteringTwiceChangesNothing) {
    Scan scan = makeScan({0.05f, 1.0f, kNaN, 35.0f, 2.0f});
    const DistanceFilter f = makeFilter(0.1, 30.0);
    f.filter(scan);
    const auto valid = scan.valid;
    const auto res = f.filter(scan);
    EXPECT_EQ(scan.valid, valid);
    EXPECT_EQ(res.valid_in, 2u);
    EXPECT_EQ(res.valid_out, 2u);
    EXPECT_EQ(res.removed_non_finite + res.removed_out_of_range, 0u);
}

TEST(DistanceFilter, EmptyScan) {
    Scan scan = makeScan({});
    const auto res = makeFilter(0.1, 30.0).filter(scan);
    EXPECT_EQ(res.valid_in, 0u);
    EXPECT_EQ(res.valid_out, 0u);
}

// The filter compares float ranges with float limits chosen to decide exactly as the double
// comparison of Algorithm 1 does; checked against that plain reference on random scans whose
// ranges sit on, just inside and just outside limits that floats cannot represent.
TEST(DistanceFilter, MatchesThePlainDoubleReferenceOnRandomScans) {
    std::mt19937 rng(20);
    std::uniform_real_distribution<double> limit(0.0, 40.0);
    for (int trial = 0; trial < 200; ++trial) {
        double lo = limit(rng), hi = limit(rng);
        if (trial % 3 == 0) lo = 0.1, hi = 29.999999;  // neither is a float
        if (trial % 7 == 0) lo = 0.0;
        if (lo > hi) std::swap(lo, hi);
        if (!(hi > lo)) continue;
        const float edges[] = {static_cast<float>(lo),
                               static_cast<float>(hi),
                               std::nextafter(static_cast<float>(lo), -kInf),
                               std::nextafter(static_cast<float>(lo), kInf),
                               std::nextafter(static_cast<float>(hi), -kInf),
                               std::nextafter(static_cast<float>(hi), kInf),
                               kNaN,
                               kInf,
                               -kInf,
                               -0.0f,
                               0.0f,
                               -1.0f};
        std::uniform_int_distribution<std::size_t> pick(0, std::size(edges) + 3);
        Scan scan = makeScan(std::vector<float>(257, 1.0f));
        for (std::size_t i = 0; i < scan.size(); ++i) {
            const std::size_t k = pick(rng);
            scan.range[i] =
                k < std::size(edges) ? edges[k] : static_cast<float>(limit(rng) * 1.2 - 2.0);
            scan.valid[i] = (rng() % 5) != 0;
        }
        const Scan before = scan;
        const auto res = makeFilter(lo, hi).filter(scan);
        std::size_t in = 0, non_finite = 0, outside = 0;
        for (std::size_t i = 0; i < scan.size(); ++i) {
            const float r = before.range[i];
            bool keep = before.valid[i] != 0;
            if (keep) {
                ++in;
                if (!std::isfinite(r)) {
                    ++non_finite;
                    keep = false;
                } else if (r < lo || r > hi) {  // Algorithm 1, in double
                    ++outside;
                    keep = false;
                }
            }
            EXPECT_EQ(scan.valid[i] != 0, keep) << "r " << r << " in [" << lo << ", " << hi << "]";
        }
        EXPECT_EQ(res.valid_in, in);
        EXPECT_EQ(res.removed_non_finite, non_finite);
        EXPECT_EQ(res.removed_out_of_range, outside);
    }
}

TEST(DistanceFilter, DefaultsAreTheScansOwnLimits) {
    const DistanceFilter f;
    EXPECT_DOUBLE_EQ(f.params().min_range, 0.0);
    EXPECT_TRUE(std::isinf(f.params().max_range));
    // A 45 m return of a sensor that measures to 80 m is kept (issue 22: 30 m cut aces' returns).
    Scan scan = makeScan({0.05f, 12.0f, 45.0f, 80.0f, 81.0f});
    scan.max_range = 80.0f;
    const auto res = f.filter(scan);
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 1, 1, 1, 0}));
    EXPECT_EQ(res.removed_out_of_range, 1u);
    EXPECT_DOUBLE_EQ(res.max_range_used, 80.0);
}

TEST(DistanceFilter, ScanWithoutAMaximumKeepsEveryFiniteReturn) {
    Scan scan = makeScan({0.5f, 200.0f, kInf});
    const auto res = DistanceFilter().filter(scan);
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 1, 0}));
    EXPECT_EQ(res.removed_non_finite, 1u);
    EXPECT_TRUE(std::isinf(res.max_range_used));
}

TEST(DistanceFilter, ParameterNarrowsTheScansMaximumButNeverWidensIt) {
    Scan narrowed = makeScan({10.0f, 29.0f, 31.0f, 50.0f});
    narrowed.max_range = 40.0f;
    EXPECT_EQ(makeFilter(0.0, 30.0).filter(narrowed).removed_out_of_range, 2u);
    EXPECT_EQ(narrowed.valid, (std::vector<std::uint8_t>{1, 1, 0, 0}));
    Scan wider = makeScan({10.0f, 29.0f, 31.0f, 50.0f});
    wider.max_range = 20.0f;
    const auto res = makeFilter(0.0, 30.0).filter(wider);
    EXPECT_EQ(wider.valid, (std::vector<std::uint8_t>{1, 0, 0, 0}));
    EXPECT_DOUBLE_EQ(res.max_range_used, 20.0);
}

TEST(DistanceFilter, RejectsInconsistentParams) {
    DistanceFilter f;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_THROW(f.initialize({-0.1, 30.0}), kfd::ParameterError);
    EXPECT_THROW(f.initialize({nan, 30.0}), kfd::ParameterError);
    EXPECT_THROW(f.initialize({1.0, 1.0}), kfd::ParameterError);
    EXPECT_THROW(f.initialize({2.0, 1.0}), kfd::ParameterError);
    EXPECT_NO_THROW(f.initialize({0.1, inf}));  // +inf: the scan's own maximum
    EXPECT_THROW(f.initialize({0.1, nan}), kfd::ParameterError);
    EXPECT_NO_THROW(f.initialize({0.0, 1.0}));
    EXPECT_DOUBLE_EQ(f.params().min_range, 0.0);
    EXPECT_DOUBLE_EQ(f.params().max_range, 1.0);
}

TEST(DistanceFilter, FailedInitializeKeepsPreviousParams) {
    DistanceFilter f = makeFilter(0.5, 4.0);
    EXPECT_THROW(f.initialize({3.0, 1.0}), kfd::ParameterError);
    EXPECT_DOUBLE_EQ(f.params().min_range, 0.5);
    EXPECT_DOUBLE_EQ(f.params().max_range, 4.0);
}

}  // namespace
}  // namespace kfd
