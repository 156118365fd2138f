// Bounded work per scan for the neighbour-based baselines: a 65 536-beam scan whose points all
// lie within each other's radius (the case that took 8 GB and minutes before the caps) runs
// each baseline with O(n) memory; DBSCAN's work counters prove it never gathers more than
// min_pts neighbours per point. Timings are in docs/CHANGELOG.md, not asserted here.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "kfd/baselines/dbscan.h"
#include "kfd/baselines/neighbour_search.h"
#include "kfd/baselines/radius_outlier.h"
#include "kfd/baselines/statistical_outlier.h"
#include "test_scans.h"

namespace {

// kMaxScanBeams beams at 1 m over 1e-4 rad: every point within 0.1 mm of every other.
kfd::Scan allTogether() { return kfd::test::arc(kfd::kMaxScanBeams, 1e-4, 1.0); }

}  // namespace

TEST(BoundedWork, RadiusQueryStopsAtMaxCount) {
    const kfd::Scan s = allTogether();
    kfd::ScanPoints pts;
    pts.assign(s);
    kfd::NeighbourSearch2D tree;
    tree.build(pts.x.data(), pts.y.data(), pts.size());
    std::vector<std::uint32_t> out;
    tree.radius(pts.x[0], pts.y[0], 0.5f, out, 11);
    EXPECT_EQ(out.size(), 11u);
    tree.radius(pts.x[0], pts.y[0], 0.5f, out, 0);
    EXPECT_TRUE(out.empty());
    // Uncapped, a small neighbourhood is still returned whole.
    tree.radius(pts.x[0], pts.y[0], 0.0f, out);
    EXPECT_GE(out.size(), 1u);
}

TEST(BoundedWork, DbscanOnADenseMaxSizeScanGathersAtMostMinPtsPerPoint) {
    kfd::Scan s = allTogether();
    kfd::DbscanFilter f;  // the paper's eps 0.7 m, min_pts 10
    const auto r = f.filter(s);
    EXPECT_EQ(r.points_in, kfd::kMaxScanBeams);
    EXPECT_EQ(r.clusters, 1u);
    EXPECT_EQ(r.points_removed, 0u);
    // Every point is core: one capped query each, no full neighbour list anywhere.
    EXPECT_LE(f.stats().neighbours_visited, kfd::kMaxScanBeams * f.params().min_pts);
    // A handful of cells, joined at their first pair.
    EXPECT_LE(f.stats().pairs_tested, 100u);
}

TEST(BoundedWork, DbscanOnDenseClumpsAndNoiseKeepsTheClumpsOnly) {
    // Two dense clumps (16 384 beams each, all within eps) far apart, lone points between.
    kfd::Scan s = kfd::test::arc(40000, kfd::kPi / 2, 1.0);
    for (std::size_t i = 0; i < 16384; ++i) s.range[i] = 5.0f;
    for (std::size_t i = 40000 - 16384; i < 40000; ++i) s.range[i] = 5.0f;
    kfd::DbscanFilter::Params p;
    p.eps_m = 2.0;  // 5 m * 90 deg arc: each clump spans ~3.2 m, so not all within eps
    p.min_pts = 10;
    kfd::DbscanFilter f(p);
    const auto r = f.filter(s);
    EXPECT_GE(r.clusters, 1u);
    EXPECT_LE(f.stats().neighbours_visited, 40000u * p.min_pts);
}

TEST(BoundedWork, DbscanRejectsAnEpsBelowItsCellLimit) {
    kfd::DbscanFilter::Params p;
    p.eps_m = 1e-7;
    EXPECT_THROW(kfd::DbscanFilter{p}, kfd::ParameterError);
    p.eps_m = 1e-6;
    EXPECT_NO_THROW(kfd::DbscanFilter{p});
}

TEST(BoundedWork, RadiusOutlierOnADenseMaxSizeScanKeepsEveryPoint) {
    kfd::Scan s = allTogether();
    kfd::RadiusOutlierFilter f;
    const auto r = f.filter(s);
    EXPECT_EQ(r.points_in, kfd::kMaxScanBeams);
    EXPECT_EQ(r.points_removed, 0u);
}

TEST(BoundedWork, StatisticalOutlierOnADenseMaxSizeScanFinishes) {
    kfd::Scan s = allTogether();
    kfd::StatisticalOutlierFilter f;
    const auto r = f.filter(s);
    EXPECT_EQ(r.points_in, kfd::kMaxScanBeams);
    EXPECT_LT(r.points_removed, kfd::kMaxScanBeams);
}

TEST(BoundedWork, BaselinesTreatHugeAndNegativeRangesAsPointsWithoutPosition) {
    kfd::Scan s = kfd::test::arc(200, kfd::kPi, 2.0);
    s.range[10] = 1e30f;
    s.range[20] = -3.0f;
    s.range[30] = std::numeric_limits<float>::infinity();
    kfd::ScanPoints pts;
    pts.assign(s);
    EXPECT_EQ(pts.nonfinite.size(), 3u);
    kfd::Scan d = s;
    kfd::DbscanFilter().filter(d);
    kfd::Scan r = s;
    kfd::RadiusOutlierFilter().filter(r);
    for (const std::size_t i : {10u, 20u, 30u}) {
        EXPECT_EQ(d.valid[i], 0u) << i;
        EXPECT_EQ(r.valid[i], 0u) << i;
    }
}
