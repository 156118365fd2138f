#include "kfd/paper/clusters.h"

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

using test::makeScan;

// ---------------------------------------------------------------------------------------------
// DisjointSets

TEST(DisjointSets, AddReturnsConsecutiveIds) {
    DisjointSets s;
    EXPECT_EQ(s.size(), 0u);
    EXPECT_EQ(s.add(), 0u);
    EXPECT_EQ(s.add(), 1u);
    EXPECT_EQ(s.add(), 2u);
    EXPECT_EQ(s.size(), 3u);
    for (std::uint32_t i = 0; i < 3; ++i) EXPECT_EQ(s.find(i), i);
}

TEST(DisjointSets, UniteJoinsSetsOnce) {
    DisjointSets s;
    for (int i = 0; i < 5; ++i) s.add();
    EXPECT_TRUE(s.unite(3, 1));
    EXPECT_FALSE(s.unite(1, 3));  // already together
    EXPECT_EQ(s.find(3), s.find(1));
    EXPECT_NE(s.find(0), s.find(1));
    EXPECT_TRUE(s.unite(4, 3));
    EXPECT_EQ(s.find(4), s.find(1));
    EXPECT_FALSE(s.unite(4, 1));
    EXPECT_NE(s.find(2), s.find(4));
}

TEST(DisjointSets, RootIsTheSmallestIndex) {
    DisjointSets s;
    for (int i = 0; i < 6; ++i) s.add();
    s.unite(5, 4);
    s.unite(4, 2);
    s.unite(3, 5);
    for (const std::uint32_t i : {2u, 3u, 4u, 5u}) EXPECT_EQ(s.find(i), 2u) << i;
    EXPECT_EQ(s.find(0), 0u);
    EXPECT_EQ(s.find(1), 1u);
}

TEST(DisjointSets, LongChainIsTransitive) {
    DisjointSets s;
    const std::uint32_t n = 1000;
    for (std::uint32_t i = 0; i < n; ++i) s.add();
    for (std::uint32_t i = n - 1; i > 0; --i) EXPECT_TRUE(s.unite(i, i - 1));
    for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(s.find(i), 0u);
}

TEST(DisjointSets, ClearForgetsEverything) {
    DisjointSets s;
    s.add();
    s.add();
    s.unite(0, 1);
    s.clear();
    EXPECT_EQ(s.size(), 0u);
    EXPECT_EQ(s.add(), 0u);
    EXPECT_EQ(s.add(), 1u);
    EXPECT_NE(s.find(0), s.find(1));
}

// ---------------------------------------------------------------------------------------------
// Clusters::finalize

TEST(Clusters, FinalizeLabelsAreCompactAndInScanOrder) {
    const Scan scan = makeScan({1, 2, 3, 4, 5, 6, 7});
    DisjointSets sets;
    for (int i = 0; i < 6; ++i) sets.add();
    sets.unite(4, 1);  // provisional 1 and 4 are one cluster
    sets.unite(5, 3);
    //                                       beam:  0  1   2  3  4  5  6
    std::vector<std::int32_t> provisional{5, 4, -1, 1, 2, 3, 0};
    Clusters c;
    c.finalize(scan, provisional, sets);
    // Root of 5 is 3 -> label 0; root of 4 is 1 -> label 1; beam 3 (prov 1) -> label 1;
    // prov 2 -> label 2; prov 3 (root 3) -> label 0; prov 0 -> label 3.
    EXPECT_EQ(c.label, (std::vector<std::int32_t>{0, 1, -1, 1, 2, 0, 3}));
    ASSERT_EQ(c.count(), 4u);
    EXPECT_EQ(c.size, (std::vector<std::uint32_t>{2, 2, 1, 1}));
    EXPECT_FLOAT_EQ(c.mean_range[0], 3.5f);  // beams 0 and 5: (1 + 6) / 2
    EXPECT_FLOAT_EQ(c.mean_range[1], 3.0f);  // beams 1 and 3: (2 + 4) / 2
    EXPECT_FLOAT_EQ(c.mean_range[2], 5.0f);
    EXPECT_FLOAT_EQ(c.mean_range[3], 7.0f);
    EXPECT_EQ(c.noise, (std::vector<std::uint8_t>{0, 0, 0, 0}));
}

TEST(Clusters, FinalizeResetsPreviousResult) {
    const Scan big = makeScan({1, 1, 1, 1});
    DisjointSets sets;
    for (int i = 0; i < 4; ++i) sets.add();
    std::vector<std::int32_t> prov{0, 1, 2, 3};
    Clusters c;
    c.finalize(big, prov, sets);
    c.noise.assign(4, 1);
    ASSERT_EQ(c.count(), 4u);

    const Scan small = makeScan({2, 4});
    sets.clear();
    sets.add();
    std::vector<std::int32_t> prov2{0, 0};
    c.finalize(small, prov2, sets);
    EXPECT_EQ(c.label, (std::vector<std::int32_t>{0, 0}));
    EXPECT_EQ(c.size, (std::vector<std::uint32_t>{2}));
    EXPECT_FLOAT_EQ(c.mean_range[0], 3.0f);
    EXPECT_EQ(c.noise, (std::vector<std::uint8_t>{0}));
}

TEST(Clusters, FinalizeWithNoPoints) {
    const Scan scan = makeScan({1, 2});
    DisjointSets sets;
    std::vector<std::int32_t> prov{-1, -1};
    Clusters c;
    c.finalize(scan, prov, sets);
    EXPECT_EQ(c.count(), 0u);
    EXPECT_EQ(c.label, (std::vector<std::int32_t>{-1, -1}));
}

// ---------------------------------------------------------------------------------------------
// minClusterPoints

TEST(MinClusterPoints, FixedThresholdIgnoresRange) {
    ClusterFilterParams p;  // min_object_size_m = 0: the paper's fixed m_threshold
    p.m_threshold = 10;
    for (const double r : {0.2, 1.0, 8.0, 30.0})
        EXPECT_EQ(minClusterPoints(p, r, test::deg2rad(0.5)), 10u) << r;
}

TEST(MinClusterPoints, RangeAdaptiveIsBeamsSpannedByTheObject) {
    ClusterFilterParams p;
    p.m_threshold = 10;
    p.min_object_size_m = 0.1;
    p.min_points_floor = 3;
    const double res = test::deg2rad(1.0);  // 0.01745 rad
    // 0.1 / (2.5 * 0.01745) = 2.29 -> 3; 0.1 / (1.5 * 0.01745) = 3.82 -> 4;
    // 0.1 / (1.2 * 0.01745) = 4.77 -> 5.
    EXPECT_EQ(minClusterPoints(p, 1.5, res), 4u);
    EXPECT_EQ(minClusterPoints(p, 1.2, res), 5u);
    EXPECT_EQ(minClusterPoints(p, 0.8, res), 8u);  // 7.16 -> 8
    EXPECT_EQ(minClusterPoints(p, 2.5, res), 3u);
}

TEST(MinClusterPoints, RangeAdaptiveIsClamped) {
    ClusterFilterParams p;
    p.m_threshold = 10;
    p.min_object_size_m = 0.1;
    p.min_points_floor = 3;
    const double res = test::deg2rad(1.0);
    EXPECT_EQ(minClusterPoints(p, 0.3, res), 10u);  // 19.1 -> capped at m_threshold
    EXPECT_EQ(minClusterPoints(p, 8.0, res), 3u);   // 0.72 -> raised to the floor
    EXPECT_EQ(minClusterPoints(p, 30.0, res), 3u);
}

TEST(MinClusterPoints, FloorAboveThresholdUsesThreshold) {
    ClusterFilterParams p;
    p.m_threshold = 4;
    p.min_object_size_m = 0.1;
    p.min_points_floor = 6;
    EXPECT_EQ(minClusterPoints(p, 8.0, test::deg2rad(1.0)), 4u);
    EXPECT_EQ(minClusterPoints(p, 0.3, test::deg2rad(1.0)), 4u);
}

TEST(MinClusterPoints, DegenerateInputsFallBackToThreshold) {
    ClusterFilterParams p;
    p.m_threshold = 10;
    p.min_object_size_m = 0.1;
    EXPECT_EQ(minClusterPoints(p, 5.0, 0.0), 10u);  // one-beam scan: no resolution
    EXPECT_EQ(minClusterPoints(p, 0.0, test::deg2rad(1.0)), 10u);
}

// ---------------------------------------------------------------------------------------------
// filterClusters

Clusters makeClusters(std::vector<std::int32_t> label, std::vector<std::uint32_t> size,
                      std::vector<float> mean_range) {
    Clusters c;
    c.label = std::move(label);
    c.size = std::move(size);
    c.mean_range = std::move(mean_range);
    c.noise.assign(c.size.size(), 0);
    return c;
}

TEST(FilterClusters, InvalidatesExactlyTheNoiseClusters) {
    Scan scan = makeScan({2, 2, 2, 2, 9, 3, 3, 3, 2, 1});
    scan.valid[4] = 0;
    // Cluster 0: beams 0-3 and 8 (5 points); cluster 1: beams 5-7 (3 points); cluster 2: beam 9.
    Clusters c = makeClusters({0, 0, 0, 0, -1, 1, 1, 1, 0, 2}, {5, 3, 1}, {2.0f, 3.0f, 1.0f});
    ClusterFilterParams p;
    p.m_threshold = 4;
    EXPECT_EQ(filterClusters(p, scan, c), 4u);
    EXPECT_EQ(c.noise, (std::vector<std::uint8_t>{0, 1, 1}));
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 1, 1, 1, 0, 0, 0, 0, 1, 0}));
    // Ranges and labels are untouched.
    EXPECT_EQ(scan.range[5], 3.0f);
    EXPECT_EQ(c.label[5], 1);
}

TEST(FilterClusters, ClusterOfExactlyThresholdSurvives) {
    Scan scan = makeScan({2, 2, 2, 5, 5});
    Clusters c = makeClusters({0, 0, 0, 1, 1}, {3, 2}, {2.0f, 5.0f});
    ClusterFilterParams p;
    p.m_threshold = 3;
    EXPECT_EQ(filterClusters(p, scan, c), 2u);
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 1, 1, 0, 0}));
}

TEST(FilterClusters, RangeAdaptiveKeepsFarSmallClusters) {
    // 1-degree scan; 4 points at 8 m span 0.56 m and pass the floor of 3; 4 points at 0.8 m
    // span 5.6 cm, narrower than 0.1 m, and need 8.
    std::vector<float> r(9, 8.0f);
    for (int i = 4; i < 8; ++i) r[i] = 0.8f;
    Scan scan = makeScan(r, test::deg2rad(8.0));
    ASSERT_NEAR(scan.geometry.resolution(), test::deg2rad(1.0), 1e-15);
    Clusters c = makeClusters({0, 0, 0, 0, 1, 1, 1, 1, 2}, {4, 4, 1}, {8.0f, 0.8f, 8.0f});
    ClusterFilterParams fixed;
    fixed.m_threshold = 10;
    Scan copy = scan;
    Clusters c2 = c;
    EXPECT_EQ(filterClusters(fixed, copy, c2), 9u);  // the paper's bar removes everything

    ClusterFilterParams adaptive = fixed;
    adaptive.min_object_size_m = 0.1;
    adaptive.min_points_floor = 3;
    EXPECT_EQ(filterClusters(adaptive, scan, c), 5u);
    EXPECT_EQ(c.noise, (std::vector<std::uint8_t>{0, 1, 1}));
    EXPECT_EQ(scan.valid, (std::vector<std::uint8_t>{1, 1, 1, 1, 0, 0, 0, 0, 0}));
}

TEST(FilterClusters, NothingToRemove) {
    Scan scan = makeScan({1, 1, 1});
    Clusters c = makeClusters({0, 0, 0}, {3}, {1.0f});
    ClusterFilterParams p;
    p.m_threshold = 1;
    EXPECT_EQ(filterClusters(p, scan, c), 0u);
    EXPECT_EQ(scan.countValid(), 3u);
}

}  // namespace
}  // namespace kfd
