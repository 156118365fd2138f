#include "kfd/paper/ring_clustering.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/paper/clusters.h"
#include "test_scans.h"

namespace kfd {
namespace {

using test::deg2rad;
using test::distinctLabels;
using test::emptyScan;
using test::sameCluster;
using test::setRange;
using test::setWall;

/// 181 beams over 180 deg: 1 deg resolution, theta_threshold = 10 deg with the default factor.
constexpr std::size_t kBeams = 181;

/// t = 5 rings around a fixed r_max = 10 m: boundaries r_1 = 4.472, r_2 = 6.325, r_3 = 7.746,
/// r_4 = 8.944 m. Default d_threshold between rings 1 and 2: 2 * 4.472 * sin(5 deg) = 0.780 m.
RingClustering::Params fixedRings(double r_max = 10.0) {
    RingClustering::Params p;
    p.rings.rings = 5;
    p.rings.r_max = r_max;
    return p;
}

Clusters run(const RingClustering::Params& p, const Scan& scan,
             RingClustering::Result* result = nullptr) {
    RingClustering rc(p);
    Clusters c;
    const auto r = rc.cluster(scan, c);
    if (result) *result = r;
    return c;
}

// ---------------------------------------------------------------------------------------------
// Figure 4: blocks inside a ring split at angle gaps.

TEST(RingClustering, SplitsAtAngleGap) {
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 20, 40, 2.0);  // ring 1
    setRange(scan, 52, 70, 2.0);  // 12 deg further on: gap > theta
    RingClustering::Result res;
    const Clusters c = run(fixedRings(), scan, &res);
    EXPECT_EQ(c.count(), 2u);
    EXPECT_EQ(res.blocks, 2u);
    EXPECT_EQ(distinctLabels(c.label, 20, 40), 1u);
    EXPECT_EQ(distinctLabels(c.label, 52, 70), 1u);
    EXPECT_FALSE(sameCluster(c, 40, 52));
    EXPECT_EQ(c.size, (std::vector<std::uint32_t>{21, 19}));
}

TEST(RingClustering, GapOfExactlyThetaDoesNotSplit) {
    for (const std::size_t second : {50u, 51u}) {  // gap of 10 deg (= theta) and 11 deg
        Scan scan = emptyScan(kBeams, kPi);
        setRange(scan, 20, 40, 2.0);
        setRange(scan, second, 70, 2.0);
        const Clusters c = run(fixedRings(), scan);
        EXPECT_EQ(c.count(), second == 50u ? 1u : 2u) << "second block at " << second;
    }
}

TEST(RingClustering, PointsOfAnotherRingOpenAnAngleGap) {
    // Ring 1 is interrupted by 11 beams of ring 5 (not adjacent): three clusters.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 20, 40, 2.0);
    setRange(scan, 41, 51, 9.5);
    setRange(scan, 52, 70, 2.0);
    RingClustering::Result res;
    const Clusters c = run(fixedRings(), scan, &res);
    EXPECT_EQ(c.count(), 3u);
    EXPECT_EQ(res.blocks, 3u);
    EXPECT_FALSE(sameCluster(c, 40, 52));
    EXPECT_FALSE(sameCluster(c, 45, 40));
}

TEST(RingClustering, InvalidBeamsInsideABlockDoNotSplitIt) {
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 20, 70, 2.0);
    test::invalidate(scan, 30, 38);  // 9 missing beams: 10 deg between the valid neighbours
    const Clusters c = run(fixedRings(), scan);
    EXPECT_EQ(c.count(), 1u);
    EXPECT_EQ(c.label[30], -1);
    EXPECT_EQ(c.size[0], 51u - 9u);
}

TEST(RingClustering, ThetaIsFactorTimesResolution) {
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 20, 40, 2.0);
    setRange(scan, 46, 70, 2.0);  // 6 deg gap
    auto p = fixedRings();
    RingClustering::Result res;
    EXPECT_EQ(run(p, scan, &res).count(), 1u);
    EXPECT_NEAR(res.theta_threshold, deg2rad(10.0), 1e-12);
    p.angle_gap_factor = 5.0;  // theta = 5 deg < 6 deg
    EXPECT_EQ(run(p, scan, &res).count(), 2u);
    EXPECT_NEAR(res.theta_threshold, deg2rad(5.0), 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Figure 5: a surface crossing a ring boundary is merged across rings.

TEST(RingClustering, MergesWallAcrossRingBoundary) {
    // A flat wall 4 m ahead over -30..30 deg: 4.0 m in front (ring 1), 4.62 m at the ends
    // (ring 2, beyond r_1 = 4.472 m). Three blocks: ring 2 left, ring 1 middle, ring 2 right.
    Scan scan = emptyScan(kBeams, kPi);
    setWall(scan, 60, 120, 4.0);
    RingClustering::Result res;
    const Clusters c = run(fixedRings(), scan, &res);
    EXPECT_EQ(res.blocks, 3u);
    EXPECT_EQ(res.merges, 2u);
    EXPECT_EQ(c.count(), 1u);
    EXPECT_EQ(distinctLabels(c.label, 60, 120), 1u);
    EXPECT_EQ(c.size[0], 61u);
}

TEST(RingClustering, MergesAcrossSeveralRings) {
    // A wall seen obliquely spans rings 2 to 5; it stays one cluster.
    Scan scan = emptyScan(kBeams, kPi);
    setWall(scan, 30, 150, 5.0);  // 5 m ahead, 10 m at +-60 deg
    RingClustering::Result res;
    const Clusters c = run(fixedRings(), scan, &res);
    EXPECT_GE(res.blocks, 7u);
    EXPECT_EQ(c.count(), 1u);
}

TEST(RingClustering, AutomaticRMaxIsTheFarthestPoint) {
    Scan scan = emptyScan(kBeams, kPi);
    setWall(scan, 30, 150, 5.0);
    auto p = fixedRings(0.0);
    RingClustering::Result res;
    const Clusters c = run(p, scan, &res);
    EXPECT_NEAR(res.r_max, 5.0 / std::cos(deg2rad(60.0)), 1e-5);
    EXPECT_EQ(c.count(), 1u);
}

// ---------------------------------------------------------------------------------------------
// Figure 6: blocks of adjacent rings that fail Formula 9 or Formula 10 stay apart.

TEST(RingClustering, NotMergedWhenDistanceTestFails) {
    // Adjacent beams (1 deg) at 4.4 m (ring 1) and 5.3 m (ring 2): d = 0.90 m > 0.78 m.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 70, 4.4);
    setRange(scan, 71, 100, 5.3);
    RingClustering::Result res;
    const Clusters c = run(fixedRings(), scan, &res);
    EXPECT_EQ(res.blocks, 2u);
    EXPECT_EQ(res.merges, 0u);
    EXPECT_EQ(c.count(), 2u);
    EXPECT_FALSE(sameCluster(c, 70, 71));
}

TEST(RingClustering, MergedWhenDistanceTestPasses) {
    // 4.4 m and 5.1 m: d = 0.70 m <= 0.78 m.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 70, 4.4);
    setRange(scan, 71, 100, 5.1);
    const Clusters c = run(fixedRings(), scan);
    EXPECT_EQ(c.count(), 1u);
}

TEST(RingClustering, ExplicitMergeDistance) {
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 70, 4.4);
    setRange(scan, 71, 100, 5.3);  // d = 0.90 m
    auto p = fixedRings();
    p.merge_distance_m = 1.0;
    EXPECT_EQ(run(p, scan).count(), 1u);
    p.merge_distance_m = 0.85;
    EXPECT_EQ(run(p, scan).count(), 2u);
}

TEST(RingClustering, DefaultMergeDistanceIsChordAtTheRingBoundary) {
    // Between rings 2 and 3 the boundary is r_2 = 6.325 m: d_threshold = 2 * 6.325 * sin(5 deg)
    // = 1.102 m. Points at 6.0 m (ring 2) and 7.0 m (ring 3), 1 deg apart: d = 1.006 m.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 70, 6.0);
    setRange(scan, 71, 100, 7.0);
    EXPECT_EQ(run(fixedRings(), scan).count(), 1u);
    // 6.0 m and 7.2 m: d = 1.205 m > 1.102 m.
    setRange(scan, 71, 100, 7.2);
    EXPECT_EQ(run(fixedRings(), scan).count(), 2u);
}

TEST(RingClustering, NotMergedWhenAngleTestFails) {
    // 12 deg between the blocks' closest ends > theta = 10 deg, however close in range.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 70, 4.4);
    setRange(scan, 82, 100, 4.6);
    auto p = fixedRings();
    p.merge_distance_m = 100.0;  // the distance test always passes
    RingClustering::Result res;
    const Clusters c = run(p, scan, &res);
    EXPECT_EQ(res.merges, 0u);
    EXPECT_EQ(c.count(), 2u);
    // 9 deg apart: merged.
    Scan near = emptyScan(kBeams, kPi);
    setRange(near, 40, 70, 4.4);
    setRange(near, 79, 100, 4.6);
    EXPECT_EQ(run(p, near).count(), 1u);
}

TEST(RingClustering, MergesAtExactlyThetaAcrossRings) {
    // Formula 9 accepts |theta_a - theta_b| <= theta_threshold: closest ends exactly 10 deg apart.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 70, 4.4);
    setRange(scan, 80, 100, 4.6);
    auto p = fixedRings();
    p.merge_distance_m = 100.0;
    EXPECT_EQ(run(p, scan).count(), 1u);
}

TEST(RingClustering, MergesAtExactlyThetaAcrossRingsNearTheFirstBeam) {
    // theta / resolution rounds to 9.999999999999998 for e.g. 62, 123, 244 or 245 beams over
    // 180 deg; blocks whose closest ends are exactly theta apart must still be compared.
    // Ring 1 at 4.4 m on beams 0-3, ring 2 at 4.6 m on beams 13-20: one cluster.
    for (const std::size_t beams : {62u, 123u, 181u, 244u, 245u, 361u}) {
        for (const bool swap : {false, true}) {
            Scan scan = emptyScan(beams, kPi);
            setRange(scan, 0, 3, swap ? 4.6 : 4.4);
            setRange(scan, 13, 20, swap ? 4.4 : 4.6);  // closest ends exactly 10 beams apart
            auto p = fixedRings();
            p.merge_distance_m = 100.0;
            EXPECT_EQ(run(p, scan).count(), 1u) << beams << " beams, swap " << swap;
        }
        // Inside one ring the same gap keeps one block.
        Scan same_ring = emptyScan(beams, kPi);
        setRange(same_ring, 0, 3, 4.4);
        setRange(same_ring, 13, 20, 4.4);
        EXPECT_EQ(run(fixedRings(), same_ring).count(), 1u) << beams << " beams";
    }
}

TEST(RingClustering, NonAdjacentRingsNeverMerge) {
    // Ring 1 (4.4 m) next to ring 3 (7.0 m): no Formula 9/10 test between rings 1 and 3.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 70, 4.4);
    setRange(scan, 71, 100, 7.0);
    auto p = fixedRings();
    p.merge_distance_m = 100.0;
    EXPECT_EQ(run(p, scan).count(), 2u);
}

TEST(RingClustering, OnlyClosestEndpointsAreCompared) {
    // The published rule compares the blocks' closest-angle end points. A 3-beam block in ring
    // 2 sitting in the middle of a long ring-1 block is 15 deg from both of its ends, so it is
    // not merged even though its neighbours are 1 deg away (ring 1 has no angle gap there
    // because the ring-2 beams are within theta).
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 69, 4.4);
    setRange(scan, 70, 72, 4.6);
    setRange(scan, 73, 100, 4.4);
    auto p = fixedRings();
    p.merge_distance_m = 100.0;
    const Clusters c = run(p, scan);
    EXPECT_EQ(c.count(), 2u);
    EXPECT_TRUE(sameCluster(c, 40, 100));
    EXPECT_FALSE(sameCluster(c, 69, 70));
}

// ---------------------------------------------------------------------------------------------
// 360-degree scanners: the +-pi seam.

TEST(RingClustering, ClusterAcrossTheSeamIsOneCluster) {
    for (const double aperture : {test::fullCircleAperture(360), 2.0 * kPi}) {
        const Scan scan = test::seamObjectScan(360, aperture);  // 350-359 and 0-9, 100-150
        RingClustering::Result res;
        const Clusters c = run(fixedRings(), scan, &res);
        EXPECT_EQ(c.count(), 2u) << "aperture " << aperture;
        EXPECT_TRUE(sameCluster(c, 0, 359));
        EXPECT_FALSE(sameCluster(c, 0, 100));
        EXPECT_EQ(res.merges, 1u);
    }
}

TEST(RingClustering, SeamMergeAcrossRings) {
    // Ring 1 (4.4 m) and ring 2 (4.6 m) meet across the seam, 1 deg apart. Each ring has a
    // second block far from the seam (ring 1 at 100-120, ring 2 at 200-220), so the blocks at
    // the seam are not both the first (or both the last) of their rings.
    for (const bool ring1_at_end : {true, false}) {
        Scan scan = emptyScan(360, test::fullCircleAperture(360));
        setRange(scan, 340, 359, ring1_at_end ? 4.4 : 4.6);
        setRange(scan, 0, 20, ring1_at_end ? 4.6 : 4.4);
        setRange(scan, 100, 120, 4.4);
        setRange(scan, 200, 220, 4.6);
        const Clusters c = run(fixedRings(), scan);
        EXPECT_EQ(c.count(), 3u) << ring1_at_end;
        EXPECT_TRUE(sameCluster(c, 359, 0)) << ring1_at_end;
    }
}

TEST(RingClustering, SeamRespectsTheAngleGap) {
    // 360 beams, theta = 10 deg: from beam 353 to beam 6 across the seam is 13 deg.
    const Scan scan = test::seamGapScan(360);  // 340-353 and 6-20
    EXPECT_EQ(run(fixedRings(), scan).count(), 2u);
}

TEST(RingClustering, NoSeamOnAHalfCircleScanner) {
    // 180-degree field of view: the first and last beams are 180 deg apart.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 0, 9, 3.0);
    setRange(scan, 171, 180, 3.0);
    EXPECT_EQ(run(fixedRings(), scan).count(), 2u);
}

TEST(RingClustering, SeamPositionDoesNotChangeTheClusters) {
    // A block joined across the seam of a 360-degree scan is one block: its ends are the outer
    // ends of the two halves, not beams 0 and N-1. Ring 1 at 4.0 m on beams 340-355 and 2-20
    // (one block through the seam), ring 2 at 4.6 m on beams 356-359 and 0-1, nested inside
    // it (16 deg from its ends): 2 clusters, as in the same scene turned by 180 deg (see
    // OnlyClosestEndpointsAreCompared).
    auto scene = [](std::size_t shift) {
        Scan scan = emptyScan(360, test::fullCircleAperture(360));
        auto set = [&](std::size_t first, std::size_t last, double r) {
            for (std::size_t i = first; i <= last; ++i)
                setRange(scan, (i + shift) % 360, (i + shift) % 360, r);
        };
        set(340, 355, 4.0);
        set(362, 380, 4.0);
        set(356, 361, 4.6);
        return scan;
    };
    const Clusters at_seam = run(fixedRings(), scene(0));
    const Clusters turned = run(fixedRings(), scene(180));
    EXPECT_EQ(turned.count(), 2u);
    EXPECT_EQ(at_seam.count(), turned.count());
}

TEST(RingClustering, FullRoomIsOneCluster) {
    const Scan scan = test::circle(360, 3.0);
    RingClustering::Result res;
    const Clusters c = run(fixedRings(0.0), scan, &res);
    EXPECT_EQ(c.count(), 1u);
    EXPECT_EQ(c.size[0], 360u);
}

// ---------------------------------------------------------------------------------------------
// The known shortfall of the published algorithm.

TEST(RingClustering, SpikeInFrontOfWallJoinsTheWallAsPublished) {
    // Indoors with a far return (an open door at 28 m), r_max = 28 m puts r_1 at 12.5 m: the
    // wall at 3 m and a one-beam spike at 1.5 m are both in ring 1 with no angle gap between
    // them, so Algorithm 2 as published keeps the spike in the wall's cluster (the range-aware
    // variant separates it).
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 40, 140, 3.0);
    test::insertSpike(scan, 90, 1.5);
    setRange(scan, 170, 180, 28.0);
    RingClustering::Result res;
    const Clusters c = run(fixedRings(0.0), scan, &res);
    EXPECT_NEAR(res.r_max, 28.0, 1e-6);
    EXPECT_TRUE(sameCluster(c, 89, 90));
    EXPECT_TRUE(sameCluster(c, 90, 91));
    EXPECT_EQ(c.size[static_cast<std::size_t>(c.label[90])], 101u);
}

// ---------------------------------------------------------------------------------------------
// Bookkeeping.

TEST(RingClustering, InvalidBeamsAreUnlabelled) {
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 10, 20, 2.0);
    const Clusters c = run(fixedRings(), scan);
    for (std::size_t i = 0; i < kBeams; ++i) EXPECT_EQ(c.label[i] >= 0, i >= 10 && i <= 20) << i;
}

TEST(RingClustering, EmptyAndDegenerateScans) {
    Clusters c;
    RingClustering rc(fixedRings(0.0));
    Scan none = emptyScan(kBeams, kPi);
    rc.cluster(none, c);
    EXPECT_EQ(c.count(), 0u);
    EXPECT_EQ(c.label, std::vector<std::int32_t>(kBeams, -1));

    const Scan one = test::makeScan({2.0f});
    rc.cluster(one, c);
    EXPECT_EQ(c.count(), 1u);
    EXPECT_EQ(c.label, std::vector<std::int32_t>{0});

    const Scan zero = test::makeScan({});
    rc.cluster(zero, c);
    EXPECT_EQ(c.count(), 0u);
    EXPECT_TRUE(c.label.empty());
}

TEST(RingClustering, MirroredScanGivesTheSamePartition) {
    std::mt19937 rng(5);
    for (int k = 0; k < 20; ++k) {
        Scan scan = test::randomScan(rng, 181, kPi);
        Scan mirrored = scan;
        mirrored.geometry.right_to_left = false;
        ASSERT_TRUE(test::samePartition(run(fixedRings(0.0), scan).label,
                                        run(fixedRings(0.0), mirrored).label));
    }
}

TEST(RingClustering, ReusedInstanceMatchesAFreshOne) {
    std::mt19937 rng(11);
    RingClustering reused(fixedRings(0.0));
    Clusters c;
    for (int k = 0; k < 30; ++k) {
        const std::size_t beams = k % 2 ? 360 : 181;
        const double aperture = k % 2 ? test::fullCircleAperture(360) : kPi;
        const Scan scan = test::randomScan(rng, beams, aperture);
        reused.cluster(scan, c);
        const Clusters fresh = run(fixedRings(0.0), scan);
        ASSERT_EQ(c.label, fresh.label) << k;
        ASSERT_EQ(c.size, fresh.size) << k;
    }
}

TEST(RingClustering, RejectsBadParams) {
    auto bad = [](auto mutate) {
        RingClustering::Params p;
        mutate(p);
        EXPECT_THROW(RingClustering{p}, kfd::ParameterError);
    };
    bad([](auto& p) { p.angle_gap_factor = 0.0; });
    bad([](auto& p) { p.angle_gap_factor = -1.0; });
    bad([](auto& p) { p.angle_gap_factor = std::nan(""); });
    bad([](auto& p) { p.merge_distance_m = -0.1; });
    bad([](auto& p) { p.merge_distance_m = std::nan(""); });
    bad([](auto& p) { p.rings.rings = 0; });
    bad([](auto& p) { p.rings.r_max = -1.0; });
}

// ---------------------------------------------------------------------------------------------
// Fast implementation against a plain O(n^2) transcription of Algorithm 2.

/// Algorithm 2 as written in ring_clustering.h, with no attempt at speed: rings by Formula 8,
/// blocks per ring split at angle gaps > theta (joined across the seam when the field of view
/// closes the circle), then every pair of blocks in adjacent rings is tested on its
/// closest-angle end points with Formulas 9 and 10. Returns a label per beam (-1 = invalid).
std::vector<std::int32_t> referenceAlgorithm2(const Scan& scan, const RingClustering::Params& p) {
    const std::size_t n = scan.size();
    const std::size_t t = p.rings.rings;
    const double res = scan.geometry.resolution();
    const double theta = p.angle_gap_factor * res;
    const double tol = 1e-12;
    const bool wraps = n > 1 && scan.geometry.seamGap() <= theta + tol;
    auto angle = [&](std::size_t a, std::size_t b) {  // angle between beams a and b
        const double d = static_cast<double>(a > b ? a - b : b - a) * res;
        return wraps ? std::min(d, 2.0 * kPi - d) : d;
    };

    // Formulas 6-8.
    double r_max = p.rings.r_max;
    if (r_max <= 0.0)
        for (std::size_t i = 0; i < n; ++i)
            if (scan.valid[i]) r_max = std::max(r_max, static_cast<double>(scan.range[i]));
    std::vector<std::size_t> ring(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        if (!scan.valid[i] || r_max <= 0.0) continue;
        const double r = scan.range[i];
        const double q = std::ceil(static_cast<double>(t) * (r * r) / (r_max * r_max));
        ring[i] = static_cast<std::size_t>(std::clamp(q, 1.0, static_cast<double>(t))) - 1;
    }

    // Sec. 3.2.2: blocks. A block is a list of beams in angle order.
    struct Block {
        std::size_t ring;
        std::vector<std::size_t> beams;
    };
    std::vector<Block> blocks;
    for (std::size_t k = 0; k < t; ++k) {
        std::vector<std::size_t> pts;
        for (std::size_t i = 0; i < n; ++i)
            if (scan.valid[i] && ring[i] == k) pts.push_back(i);
        const std::size_t first_block = blocks.size();
        for (std::size_t m = 0; m < pts.size(); ++m) {
            if (m == 0 || static_cast<double>(pts[m] - pts[m - 1]) * res > theta + tol)
                blocks.push_back(Block{k, {}});
            blocks.back().beams.push_back(pts[m]);
        }
        // The seam: the ring's last block continues into its first one.
        const std::size_t made = blocks.size() - first_block;
        if (wraps && made >= 2 && angle(pts.back(), pts.front()) <= theta + tol) {
            Block& last = blocks.back();
            Block& first = blocks[first_block];
            last.beams.insert(last.beams.end(), first.beams.begin(), first.beams.end());
            first.beams = last.beams;
            blocks.pop_back();
        }
    }

    // Union-find over blocks.
    std::vector<std::size_t> parent(blocks.size());
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](std::size_t a) {
        while (parent[a] != a) a = parent[a];
        return a;
    };

    // Sec. 3.2.3: every pair of blocks in adjacent rings, closest-angle end points.
    for (std::size_t a = 0; a < blocks.size(); ++a) {
        for (std::size_t b = 0; b < blocks.size(); ++b) {
            if (blocks[b].ring != blocks[a].ring + 1) continue;
            const std::size_t k = blocks[a].ring;  // inner ring, 0-based
            const double r_k =
                std::sqrt(static_cast<double>(k + 1) / static_cast<double>(t)) * r_max;
            const double d_thr =
                p.merge_distance_m > 0.0 ? p.merge_distance_m : 2.0 * r_k * std::sin(0.5 * theta);
            const std::size_t ea[2] = {blocks[a].beams.front(), blocks[a].beams.back()};
            const std::size_t eb[2] = {blocks[b].beams.front(), blocks[b].beams.back()};
            double best = 1e300;
            std::size_t ia = ea[0], ib = eb[0];
            for (const auto i : ea)
                for (const auto j : eb)
                    if (angle(i, j) < best) {
                        best = angle(i, j);
                        ia = i;
                        ib = j;
                    }
            if (best > theta + tol) continue;  // Formula 9
            const double ra = scan.range[ia], rb = scan.range[ib];
            const double d =
                std::sqrt(std::max(0.0, ra * ra + rb * rb - 2.0 * ra * rb * std::cos(best)));
            if (d > d_thr) continue;  // Formula 10
            parent[find(a)] = find(b);
        }
    }

    std::vector<std::int32_t> label(n, -1);
    for (std::size_t b = 0; b < blocks.size(); ++b)
        for (const auto i : blocks[b].beams) label[i] = static_cast<std::int32_t>(find(b));
    return label;
}

struct RandomCase {
    Scan scan;
    RingClustering::Params params;
};

RandomCase randomCase(std::mt19937& rng) {
    std::uniform_int_distribution<std::size_t> beams(20, 400);
    std::uniform_int_distribution<int> pick(0, 99);
    const std::size_t n = beams(rng);
    double aperture = kPi;
    switch (pick(rng) % 5) {
        case 0:
            aperture = kPi;
            break;
        case 1:
            aperture = deg2rad(270.0);
            break;
        case 2:
            aperture = test::fullCircleAperture(n);
            break;
        case 3:
            aperture = 2.0 * kPi;
            break;
        default:
            aperture = deg2rad(240.0);
            break;
    }
    const double factors[] = {2.5, 3.0, 5.0, 7.5, 10.0, 10.5};
    RandomCase rc{test::randomScan(rng, n, aperture), {}};
    rc.params.rings.rings = 1 + static_cast<std::size_t>(pick(rng) % 8);
    rc.params.rings.r_max = pick(rng) < 25 ? 6.0 : 0.0;  // sometimes clamp far points
    rc.params.angle_gap_factor = factors[pick(rng) % 6];
    rc.params.merge_distance_m = pick(rng) < 25 ? 0.5 : 0.0;
    return rc;
}

bool closesTheCircle(const RandomCase& rc) {
    const ScanGeometry& g = rc.scan.geometry;
    return g.seamGap() <= rc.params.angle_gap_factor * g.resolution() + 1e-12;
}

/// Compares RingClustering with referenceAlgorithm2 on `cases` random scans whose field of
/// view closes the circle (`wrapping`) or not.
void compareWithReference(std::uint32_t seed, bool wrapping, int cases) {
    std::mt19937 rng(seed);
    RingClustering fast;
    Clusters c;
    int done = 0, with_invalid = 0;
    while (done < cases) {
        const RandomCase rc = randomCase(rng);
        if (closesTheCircle(rc) != wrapping) continue;
        ++done;
        with_invalid += rc.scan.countValid() < rc.scan.size();
        fast.initialize(rc.params);
        fast.cluster(rc.scan, c);
        const auto expected = referenceAlgorithm2(rc.scan, rc.params);
        ASSERT_TRUE(test::samePartition(c.label, expected))
            << "case " << done << ": " << rc.scan.size() << " beams, aperture "
            << rc.scan.geometry.aperture << ", t " << rc.params.rings.rings << ", factor "
            << rc.params.angle_gap_factor << ", r_max " << rc.params.rings.r_max << ", d_threshold "
            << rc.params.merge_distance_m;
    }
    EXPECT_GT(with_invalid, cases / 2);  // the scans do exercise invalid beams
}

TEST(RingClustering, MatchesBruteForceReference) { compareWithReference(2023, false, 400); }

TEST(RingClustering, MatchesBruteForceReferenceOn360Scans) { compareWithReference(77, true, 400); }

}  // namespace
}  // namespace kfd
