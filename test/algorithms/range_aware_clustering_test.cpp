#include "kfd/algorithms/range_aware_clustering.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
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

/// 361 beams over 180 deg: 0.5 deg resolution, theta_threshold = 5 deg with the default factor.
/// The jump distance is then at most min(r) * sin(5 deg) / sin(10 deg) + 0.09 = 0.5 * min(r) +
/// 0.09 m, so depth steps of more than half the nearer range (+ 9 cm) always separate objects.
/// (At 1 deg resolution they do not: see DepthStepsAtOneDegreeResolution.)
constexpr std::size_t kBeams = 361;

Clusters run(const RangeAwareClustering::Params& p, const Scan& scan,
             RangeAwareClustering::Result* result = nullptr) {
    RangeAwareClustering rc(p);
    Clusters c;
    const auto r = rc.cluster(scan, c);
    if (result) *result = r;
    return c;
}

Clusters run(const Scan& scan, RangeAwareClustering::Result* result = nullptr) {
    return run(RangeAwareClustering::Params{}, scan, result);
}

TEST(RangeAwareClustering, JumpDistanceFormula) {
    // D = min(ra, rb) * sin(min(dtheta, lambda / 2)) / sin(lambda) + 3 * sigma.
    // lambda = 30 deg, sigma = 0.1 m: below the cap, dtheta = 10 deg gives
    // D = 1 * sin(10 deg) / 0.5 + 0.3 = 0.64730 m; at and beyond the cap (15 deg)
    // D = 1 * sin(15 deg) / 0.5 + 0.3 = 0.81764 m.
    RangeAwareClustering::Params p;
    p.jump_lambda_deg = 30.0;
    p.jump_sigma_m = 0.1;
    const RangeAwareClustering rc(p);
    EXPECT_NEAR(rc.jumpDistance(1.0, 2.0, deg2rad(10.0)), 0.647296, 1e-6);
    EXPECT_NEAR(rc.jumpDistance(2.0, 1.0, deg2rad(10.0)), 0.647296, 1e-6);  // symmetric
    EXPECT_NEAR(rc.jumpDistance(1.0, 2.0, deg2rad(15.0)), 0.817638, 1e-6);
    EXPECT_NEAR(rc.jumpDistance(1.0, 2.0, deg2rad(30.0)), 0.817638, 1e-6);  // capped
    EXPECT_NEAR(rc.jumpDistance(4.0, 10.0, deg2rad(10.0)), 4 * 0.347296 + 0.3, 1e-5);
    EXPECT_NEAR(rc.jumpDistance(1.0, 2.0, 0.0), 0.3, 1e-12);  // noise floor only
    // Defaults (lambda = 10 deg, sigma = 0.03 m): 3 * sin(1 deg) / sin(10 deg) + 0.09.
    const RangeAwareClustering def;
    EXPECT_NEAR(def.jumpDistance(3.0, 3.0, deg2rad(1.0)), 0.3915, 1e-4);
}

TEST(RangeAwareClustering, SpikeInFrontOfWallIsItsOwnCluster) {
    // A flat wall 3 m ahead over -30..30 deg, a one-beam spike at 1.5 m straight ahead.
    Scan scan = emptyScan(kBeams, kPi);
    setWall(scan, 120, 240, 3.0);
    test::insertSpike(scan, 180, 1.5);
    const Clusters c = run(scan);
    EXPECT_EQ(c.count(), 2u);
    // The wall is ONE cluster on both sides of the spike.
    EXPECT_EQ(distinctLabels(c.label, 120, 179), 1u);
    EXPECT_TRUE(sameCluster(c, 179, 181));
    EXPECT_TRUE(sameCluster(c, 120, 240));
    EXPECT_FALSE(sameCluster(c, 179, 180));
    EXPECT_FALSE(sameCluster(c, 180, 181));
    EXPECT_EQ(c.size[static_cast<std::size_t>(c.label[180])], 1u);
    EXPECT_EQ(c.size[static_cast<std::size_t>(c.label[120])], 120u);
}

TEST(RangeAwareClustering, SpikeBehindWallIsItsOwnCluster) {
    Scan scan = emptyScan(kBeams, kPi);
    setWall(scan, 120, 240, 3.0);
    test::insertSpike(scan, 150, 6.0);  // a return through a gap
    const Clusters c = run(scan);
    EXPECT_EQ(c.count(), 2u);
    EXPECT_TRUE(sameCluster(c, 149, 151));
    EXPECT_FALSE(sameCluster(c, 149, 150));
}

TEST(RangeAwareClustering, ObjectsAtDifferentDepthsAdjacentInAngleAreSplit) {
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 140, 180, 2.0);
    setRange(scan, 181, 220, 4.0);
    const Clusters c = run(scan);
    EXPECT_EQ(c.count(), 2u);
    EXPECT_EQ(distinctLabels(c.label, 140, 180), 1u);
    EXPECT_EQ(distinctLabels(c.label, 181, 220), 1u);
    EXPECT_FALSE(sameCluster(c, 180, 181));
    EXPECT_EQ(c.size, (std::vector<std::uint32_t>{41, 40}));
}

TEST(RangeAwareClustering, NarrowOccluderKeepsTheWallWhole) {
    // A post 2.5 m away hides 7 beams (3.5 deg) of a wall 5 m away: the wall's two sides are
    // 4 deg apart (< theta = 5 deg) and join again; the post is its own cluster.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 100, 260, 5.0);
    setRange(scan, 170, 176, 2.5);
    const Clusters c = run(scan);
    EXPECT_EQ(c.count(), 2u);
    EXPECT_TRUE(sameCluster(c, 169, 177));
    EXPECT_EQ(distinctLabels(c.label, 170, 176), 1u);
    EXPECT_FALSE(sameCluster(c, 169, 170));
}

TEST(RangeAwareClustering, WideOccluderSplitsTheWall) {
    // 16 beams (8 deg) hidden: more than theta, so the wall's two sides are two clusters.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 100, 260, 5.0);
    setRange(scan, 170, 185, 2.5);
    const Clusters c = run(scan);
    EXPECT_EQ(c.count(), 3u);
    EXPECT_FALSE(sameCluster(c, 169, 186));
}

TEST(RangeAwareClustering, ObliqueWallStaysOneCluster) {
    // A flat wall 2 m ahead seen over +-60 deg: 4 m at the ends, never closer than 30 deg to
    // grazing. At 1 deg and at 0.25 deg resolution.
    for (const std::size_t beams : {121u, 481u}) {
        const Clusters c = run(test::flatWall(beams, deg2rad(120.0), 2.0));
        EXPECT_EQ(c.count(), 1u) << beams;
        EXPECT_EQ(c.size[0], beams);
    }
}

TEST(RangeAwareClustering, LambdaAndSigmaControlTheBreakpoint) {
    // 3.0 m next to 3.4 m, 1 deg apart (181 beams): d = 0.404 m. theta = one beam, so only
    // direct neighbours are compared.
    Scan scan = emptyScan(181, kPi);
    setRange(scan, 20, 40, 3.0);
    setRange(scan, 41, 60, 3.4);
    RangeAwareClustering::Params p;  // lambda 10 deg: D = 0.3915 m
    p.angle_gap_factor = 1.0;
    EXPECT_EQ(run(p, scan).count(), 2u);
    p.jump_lambda_deg = 5.0;  // D = 3 * sin(1 deg) / sin(5 deg) + 0.09 = 0.691 m
    EXPECT_EQ(run(p, scan).count(), 1u);
    p.jump_lambda_deg = 10.0;
    p.jump_sigma_m = 0.05;  // D = 0.3015 + 0.15 = 0.4515 m
    EXPECT_EQ(run(p, scan).count(), 1u);
}

TEST(RangeAwareClustering, SplitsAtAngleGap) {
    for (const std::size_t second : {50u, 51u}) {  // 10 deg (= theta) and 11 deg
        Scan scan = emptyScan(kBeams, kPi);
        setRange(scan, 20, 40, 2.0);
        setRange(scan, second, 70, 2.0);
        EXPECT_EQ(run(scan).count(), second == 50u ? 1u : 2u) << second;
    }
}

TEST(RangeAwareClustering, BridgingPointJoinsClusters) {
    // 1 deg resolution. 3.0 m and 3.5 m are too far apart to link (0.503 m > 0.3915 m); the
    // next point at 3.25 m reaches both (0.273 m <= 0.693 m over 2 deg, 0.257 m <= 0.417 m
    // over 1 deg).
    Scan scan = emptyScan(181, kPi);
    setRange(scan, 10, 10, 3.0);
    setRange(scan, 11, 11, 3.5);
    setRange(scan, 12, 12, 3.25);
    RangeAwareClustering::Result res;
    const Clusters c = run(scan, &res);
    EXPECT_EQ(c.count(), 1u);
    EXPECT_EQ(res.merges, 1u);
    EXPECT_EQ(res.links, 1u);
    EXPECT_EQ(res.splits, 1u);  // beam 11 was within theta of beam 10 but too far
}

TEST(RangeAwareClustering, ThetaIsFactorTimesResolution) {
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 20, 40, 2.0);
    setRange(scan, 46, 70, 2.0);  // 6 deg gap
    RangeAwareClustering::Params p;
    RangeAwareClustering::Result res;
    EXPECT_EQ(run(p, scan, &res).count(), 1u);
    EXPECT_NEAR(res.theta_threshold, deg2rad(5.0), 1e-12);
    p.angle_gap_factor = 5.0;  // 2.5 deg < 3 deg
    EXPECT_EQ(run(p, scan, &res).count(), 2u);
    EXPECT_NEAR(res.theta_threshold, deg2rad(2.5), 1e-12);
}

TEST(RangeAwareClustering, DepthStepsAtOneDegreeResolution) {
    // At 1 deg resolution theta (10 beams) reaches lambda (10 deg). Without the lambda/2 cap
    // in jumpDistance() D would be min(ra, rb) + 0.09 m there and link objects at twice the
    // depth: (a) beam 70 at 4.0 m is 10 deg from beam 60 at 2.0 m, d = 2.06 m; (b) a 1.5 m
    // spike in front of a 3.0 m arc is 1.545 m from the arc point 10 deg later.
    Scan depths = emptyScan(181, kPi);
    setRange(depths, 20, 60, 2.0);
    setRange(depths, 61, 100, 4.0);
    EXPECT_EQ(run(depths).count(), 2u);

    Scan spike = emptyScan(181, kPi);
    setRange(spike, 30, 150, 3.0);
    test::insertSpike(spike, 90, 1.5);
    const Clusters c = run(spike);
    EXPECT_EQ(c.count(), 2u);
    EXPECT_FALSE(sameCluster(c, 90, 100));
    EXPECT_TRUE(sameCluster(c, 89, 91));
}

// ---------------------------------------------------------------------------------------------
// 360-degree scanners.

TEST(RangeAwareClustering, ClusterAcrossTheSeamIsOneCluster) {
    for (const double aperture : {test::fullCircleAperture(720), 2.0 * kPi}) {
        const Scan scan = test::seamObjectScan(720, aperture);  // 710-719 and 0-9, 100-150
        RangeAwareClustering::Result res;
        const Clusters c = run(scan, &res);
        EXPECT_EQ(c.count(), 2u) << aperture;
        EXPECT_TRUE(sameCluster(c, 0, 719));
        EXPECT_FALSE(sameCluster(c, 0, 100));
        EXPECT_GE(res.merges, 1u);
    }
}

TEST(RangeAwareClustering, SeamKeepsDifferentDepthsApart) {
    Scan scan = emptyScan(720, test::fullCircleAperture(720));
    setRange(scan, 710, 719, 3.0);
    setRange(scan, 0, 9, 6.0);
    EXPECT_EQ(run(scan).count(), 2u);
}

TEST(RangeAwareClustering, SeamRespectsTheAngleGap) {
    // 720 beams: theta = 10 beams. From beam 713 to beam 6 across the seam is 13 beams.
    Scan scan = test::seamGapScan(720);  // 700-713 and 6-20
    EXPECT_EQ(run(scan).count(), 2u);
    // From beam 713 to beam 3 is exactly 10 beams: joined.
    setRange(scan, 3, 3, 3.0);
    EXPECT_EQ(run(scan).count(), 1u);
}

TEST(RangeAwareClustering, NoSeamOnAHalfCircleScanner) {
    // 180-degree field of view: the first and the last ten beams are 180 deg apart.
    Scan scan = emptyScan(kBeams, kPi);
    setRange(scan, 0, 9, 3.0);
    setRange(scan, kBeams - 10, kBeams - 1, 3.0);
    EXPECT_EQ(run(scan).count(), 2u);
}

TEST(RangeAwareClustering, FullRoomIsOneCluster) {
    const Clusters c = run(test::circle(360, 3.0));
    EXPECT_EQ(c.count(), 1u);
    EXPECT_EQ(c.size[0], 360u);
}

// ---------------------------------------------------------------------------------------------
// Bookkeeping.

TEST(RangeAwareClustering, EmptyAndDegenerateScans) {
    RangeAwareClustering rc;
    Clusters c;
    rc.cluster(emptyScan(kBeams, kPi), c);
    EXPECT_EQ(c.count(), 0u);
    EXPECT_EQ(c.label, std::vector<std::int32_t>(kBeams, -1));
    rc.cluster(test::makeScan({2.0f}), c);
    EXPECT_EQ(c.count(), 1u);
    EXPECT_EQ(c.label, std::vector<std::int32_t>{0});
    rc.cluster(test::makeScan({}), c);
    EXPECT_EQ(c.count(), 0u);
    EXPECT_TRUE(c.label.empty());
}

TEST(RangeAwareClustering, MirroredScanGivesTheSamePartition) {
    std::mt19937 rng(5);
    for (int k = 0; k < 30; ++k) {
        const Scan scan = test::randomScan(rng, 181, kPi);
        Scan mirrored = scan;
        mirrored.geometry.right_to_left = false;
        ASSERT_TRUE(test::samePartition(run(scan).label, run(mirrored).label)) << k;
    }
}

TEST(RangeAwareClustering, ReusedInstanceMatchesAFreshOne) {
    // The cos/sin tables follow the geometry from scan to scan.
    std::mt19937 rng(11);
    RangeAwareClustering reused;
    Clusters c;
    for (int k = 0; k < 30; ++k) {
        const std::size_t beams = k % 3 == 0 ? 360 : (k % 3 == 1 ? 181 : 541);
        const double aperture =
            k % 3 == 0 ? test::fullCircleAperture(360) : (k % 3 == 1 ? kPi : deg2rad(270.0));
        const Scan scan = test::randomScan(rng, beams, aperture);
        reused.cluster(scan, c);
        const Clusters fresh = run(scan);
        ASSERT_EQ(c.label, fresh.label) << k;
    }
}

TEST(RangeAwareClustering, RejectsBadParams) {
    auto bad = [](auto mutate) {
        RangeAwareClustering::Params p;
        mutate(p);
        EXPECT_THROW(RangeAwareClustering{p}, kfd::ParameterError);
    };
    bad([](auto& p) { p.angle_gap_factor = 0.0; });
    bad([](auto& p) { p.angle_gap_factor = std::nan(""); });
    bad([](auto& p) { p.jump_lambda_deg = 0.0; });
    bad([](auto& p) { p.jump_lambda_deg = 90.0; });
    bad([](auto& p) { p.jump_lambda_deg = -5.0; });
    bad([](auto& p) { p.jump_sigma_m = -0.01; });
    bad([](auto& p) { p.jump_sigma_m = std::nan(""); });
    RangeAwareClustering::Params ok;
    ok.jump_sigma_m = 0.0;
    ok.jump_lambda_deg = 89.0;
    EXPECT_NO_THROW(RangeAwareClustering{ok});
}

// ---------------------------------------------------------------------------------------------
// Invariants on random scans. The greedy "nearest open cluster" makes a brute-force partition
// no simpler than the implementation itself, so the documented rule is checked instead:
//  - every valid beam is labelled, labels are compact and in scan order, sizes/means add up;
//  - no over-merging: each cluster is connected by links that pass the angle test and the
//    jump test (a union only ever happens along such a link);
//  - no missed neighbour: a valid point and the previous valid point within theta (also
//    across the seam) that pass the jump test with margin are in the same cluster (the previous
//    point is always the last point of an open cluster);
//  - count = valid points - links - merges.

struct LinkTest {
    const Scan& scan;
    const RangeAwareClustering& rc;
    double theta;
    bool wraps;
    /// Angle (rad) between beams a and b, the short way round when the scan closes the circle.
    double angle(std::size_t a, std::size_t b) const {
        const double d = static_cast<double>(a > b ? a - b : b - a) * scan.geometry.resolution();
        return wraps ? std::min(d, 2.0 * kPi - d) : d;
    }
    /// Euclidean distance minus the jump distance (m); <= 0 means the jump test passes.
    double excess(std::size_t a, std::size_t b) const {
        const double ra = scan.range[a], rb = scan.range[b], dt = angle(a, b);
        const double d = std::sqrt(std::max(0.0, ra * ra + rb * rb - 2.0 * ra * rb * std::cos(dt)));
        return d - rc.jumpDistance(ra, rb, dt);
    }
};

TEST(RangeAwareClustering, InvariantsOnRandomScans) {
    std::mt19937 rng(424242);
    std::uniform_int_distribution<std::size_t> beams(60, 400);
    std::uniform_int_distribution<int> pick(0, 99);
    RangeAwareClustering rc;
    Clusters c;
    const double tol = 1e-4;  // the implementation works in float
    int checked_neighbours = 0, checked_seams = 0;
    for (int k = 0; k < 300; ++k) {
        const std::size_t n = beams(rng);
        const double apertures[] = {kPi, deg2rad(270.0), test::fullCircleAperture(n), 2.0 * kPi};
        const double aperture = apertures[pick(rng) % 4];
        const double factors[] = {3.0, 5.0, 7.5, 10.0};
        RangeAwareClustering::Params p;
        p.angle_gap_factor = factors[pick(rng) % 4];
        p.jump_lambda_deg = pick(rng) < 50 ? 10.0 : 20.0;
        rc.initialize(p);
        const Scan scan = test::randomScan(rng, n, aperture);
        const auto res = rc.cluster(scan, c);
        const double theta = p.angle_gap_factor * scan.geometry.resolution();
        const LinkTest link{scan, rc, theta, scan.geometry.seamGap() <= theta + 1e-12};
        SCOPED_TRACE(::testing::Message() << "scan " << k << ": " << n << " beams, aperture "
                                          << aperture << ", factor " << p.angle_gap_factor);

        // Labels: every valid beam, compact, in order of first appearance.
        ASSERT_EQ(c.label.size(), n);
        std::int32_t next = 0;
        std::vector<std::uint32_t> size(c.count(), 0);
        std::vector<double> sum(c.count(), 0.0);
        std::size_t valid = 0;
        for (std::size_t i = 0; i < n; ++i) {
            ASSERT_EQ(c.label[i] >= 0, scan.valid[i] != 0) << i;
            if (!scan.valid[i]) continue;
            ++valid;
            ASSERT_LE(c.label[i], next) << i;
            if (c.label[i] == next) ++next;
            ++size[c.label[i]];
            sum[c.label[i]] += scan.range[i];
        }
        ASSERT_EQ(static_cast<std::size_t>(next), c.count());
        ASSERT_EQ(size, c.size);
        for (std::size_t l = 0; l < c.count(); ++l)
            ASSERT_NEAR(c.mean_range[l], sum[l] / size[l], 1e-4);
        ASSERT_EQ(c.count(), valid - res.links - res.merges);

        // No over-merging: each cluster is connected by valid links (flood fill).
        for (std::size_t l = 0; l < c.count(); ++l) {
            std::vector<std::size_t> members;
            for (std::size_t i = 0; i < n; ++i)
                if (c.label[i] == static_cast<std::int32_t>(l)) members.push_back(i);
            std::vector<std::uint8_t> reached(members.size(), 0);
            std::vector<std::size_t> stack{0};
            reached[0] = 1;
            while (!stack.empty()) {
                const std::size_t a = stack.back();
                stack.pop_back();
                for (std::size_t b = 0; b < members.size(); ++b) {
                    if (reached[b]) continue;
                    if (link.angle(members[a], members[b]) <= theta + 1e-12 &&
                        link.excess(members[a], members[b]) <= tol) {
                        reached[b] = 1;
                        stack.push_back(b);
                    }
                }
            }
            ASSERT_EQ(std::count(reached.begin(), reached.end(), 1),
                      static_cast<std::ptrdiff_t>(members.size()))
                << "cluster " << l << " is not chained by links";
        }

        // No missed neighbour.
        std::vector<std::size_t> valid_beams;
        for (std::size_t i = 0; i < n; ++i)
            if (scan.valid[i]) valid_beams.push_back(i);
        for (std::size_t m = 1; m < valid_beams.size(); ++m) {
            const std::size_t a = valid_beams[m - 1], b = valid_beams[m];
            if (static_cast<double>(b - a) * scan.geometry.resolution() > theta) continue;
            if (link.excess(a, b) > -tol) continue;
            ++checked_neighbours;
            ASSERT_EQ(c.label[a], c.label[b]) << "neighbours " << a << " and " << b;
        }
        if (link.wraps && valid_beams.size() > 1) {
            const std::size_t a = valid_beams.back(), b = valid_beams.front();
            if (link.angle(a, b) <= theta - 1e-9 && link.excess(a, b) < -tol) {
                ++checked_seams;
                ASSERT_EQ(c.label[a], c.label[b]) << "across the seam: " << a << " and " << b;
            }
        }
    }
    EXPECT_GT(checked_neighbours, 10000);
    EXPECT_GT(checked_seams, 5);
}

}  // namespace
}  // namespace kfd
