#include "kfd/baselines/dbscan.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

using test::kInf;
using test::kNaN;

DbscanFilter::Params params(double eps_m, std::size_t min_pts) {
    DbscanFilter::Params p;
    p.eps_m = eps_m;
    p.min_pts = min_pts;
    return p;
}

/// A scan of `beams` invalid beams, `step` rad apart. On an arc of radius R, beams i and j are
/// 2 R sin(|i - j| step / 2) apart (a little less than R step |i - j|).
Scan arcCanvas(std::size_t beams, double step) {
    return test::emptyScan(beams, step * static_cast<double>(beams - 1));
}

/// Indices of the valid beams of a scan.
std::vector<std::size_t> validBeams(const Scan& s) {
    std::vector<std::size_t> v;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (s.valid[i]) v.push_back(i);
    return v;
}

// --- Parameters -----------------------------------------------------------------------------

TEST(DbscanFilter, ParamsDefaultsAreThePapers) {
    const DbscanFilter::Params p;
    EXPECT_EQ(p.eps_m, 0.7);    // Sec. 4: Eps = 0.7 m
    EXPECT_EQ(p.min_pts, 10u);  // minPts = 10
    const DbscanFilter f;
    EXPECT_EQ(f.params().eps_m, 0.7);
    EXPECT_EQ(f.params().min_pts, 10u);
    const DbscanFilter g(params(0.25, 3));
    EXPECT_EQ(g.params().eps_m, 0.25);
    EXPECT_EQ(g.params().min_pts, 3u);
}

TEST(DbscanFilter, InvalidParamsThrow) {
    auto bad = [](const DbscanFilter::Params& p) {
        EXPECT_THROW(DbscanFilter{p}, kfd::ParameterError);
        DbscanFilter f;
        EXPECT_THROW(f.initialize(p), kfd::ParameterError);
    };
    for (const double eps : {0.0, -0.0, -0.7, kNaN, kInf, -kInf}) {
        SCOPED_TRACE(eps);
        bad(params(eps, 10));
    }
    bad(params(0.7, 0));
    EXPECT_NO_THROW(DbscanFilter{params(1e-6, 1)});
    EXPECT_NO_THROW(DbscanFilter{params(100.0, 100000)});
}

// --- Hand-made scans ------------------------------------------------------------------------

TEST(DbscanFilter, DenseWallStays) {
    DbscanFilter f;  // paper parameters
    Scan scan = test::flatWall(181, test::deg2rad(90.0), 3.0);
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.clusters, 1u);
    EXPECT_EQ(r.points_removed, 0u);
    EXPECT_EQ(scan.countValid(), 181u);
    ASSERT_EQ(f.labels().size(), 181u);
    EXPECT_GE(f.labels()[0], 0);
    for (std::size_t i = 0; i < 181; ++i) EXPECT_EQ(f.labels()[i], f.labels()[0]) << i;
}

TEST(DbscanFilter, IsolatedOutliersAreRemoved) {
    DbscanFilter f;
    Scan scan = test::wallWithOutliers();       // outliers at beams 20, 150 (behind), 90 (in front)
    test::insertOutliers(scan, {60, 61}, 9.0);  // a pair is still noise
    const Scan input = scan;
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.clusters, 1u);
    EXPECT_EQ(r.points_removed, 5u);
    EXPECT_EQ(scan.range, input.range);  // only valid flags change
    const std::int32_t wall = f.labels()[0];
    EXPECT_GE(wall, 0);
    for (std::size_t i = 0; i < 181; ++i) {
        const bool outlier = i == 20 || i == 150 || i == 90 || i == 60 || i == 61;
        EXPECT_EQ(scan.valid[i], outlier ? 0 : 1) << "beam " << i;
        EXPECT_EQ(f.labels()[i], outlier ? -1 : wall) << "beam " << i;
    }
}

TEST(DbscanFilter, SmallGroupIsRemovedAndMinPtsCountsThePointItself) {
    // 0.005 rad between beams: at 10 m neighbouring beams are 0.05 m apart, so a run of 10
    // beams spans 0.45 m < Eps = 0.7 m: every point of the run has the whole run (itself
    // included) as its neighbourhood.
    Scan scan = arcCanvas(400, 0.005);
    test::setRange(scan, 0, 199, 5.0);     // a dense arc
    test::setRange(scan, 300, 308, 10.0);  // 9 points: each has 9 neighbours < minPts
    test::setRange(scan, 350, 359, 10.0);  // 10 points: each has 10 = minPts (with itself)
    const Scan input = scan;

    DbscanFilter f;  // Eps 0.7 m, minPts 10
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 219u);
    EXPECT_EQ(r.clusters, 2u);
    EXPECT_EQ(r.points_removed, 9u);
    const auto& l = f.labels();
    for (std::size_t i = 300; i <= 308; ++i) {
        EXPECT_EQ(scan.valid[i], 0) << i;
        EXPECT_EQ(l[i], -1) << i;
    }
    for (std::size_t i = 0; i <= 199; ++i) EXPECT_EQ(l[i], l[0]) << i;
    for (std::size_t i = 350; i <= 359; ++i) {
        EXPECT_EQ(scan.valid[i], 1) << i;
        EXPECT_EQ(l[i], l[350]) << i;
    }
    EXPECT_GE(l[0], 0);
    EXPECT_GE(l[350], 0);
    EXPECT_NE(l[0], l[350]);

    // With minPts 9 the group of 9 is a cluster too.
    Scan again = input;
    DbscanFilter g(params(0.7, 9));
    const auto r9 = g.filter(again);
    EXPECT_EQ(r9.clusters, 3u);
    EXPECT_EQ(r9.points_removed, 0u);
    EXPECT_EQ(again.valid, input.valid);
}

/// Arc of radius 10 m with beams 0.03 rad apart (0.30 m between neighbours, 0.90 m three
/// beams apart, 1.20 m four beams apart); Eps 1 m, minPts 4.
///   core:   beams c..c+3 (each sees the 4 of them)
///   border: beam c-3 sees {itself, c, z} = 3 < minPts, and is within Eps of core beam c
///   noise:  beam z = c-6 sees {itself, border} only; it is within Eps of the border point but
///           not of any core point, and border points do not expand a cluster.
Scan borderScan(std::size_t c) {
    Scan s = arcCanvas(20, 0.03);
    test::setRange(s, c, c + 3, 10.0);
    test::setRange(s, c - 3, c - 3, 10.0);
    test::setRange(s, c - 6, c - 6, 10.0);
    return s;
}

TEST(DbscanFilter, BorderPointStaysInCluster) {
    DbscanFilter f(params(1.0, 4));
    Scan scan = borderScan(8);  // noise 2, border 5, core 8..11
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 6u);
    EXPECT_EQ(r.clusters, 1u);
    EXPECT_EQ(r.points_removed, 1u);
    const auto& l = f.labels();
    EXPECT_EQ(l[2], -1);
    EXPECT_EQ(scan.valid[2], 0);
    EXPECT_GE(l[8], 0);
    EXPECT_EQ(l[5], l[8]);  // the border point, visited (and found non-core) before any core
    EXPECT_EQ(scan.valid[5], 1);
    for (std::size_t i = 8; i <= 11; ++i) EXPECT_EQ(l[i], l[8]) << i;
}

TEST(DbscanFilter, BorderPointStaysInClusterWhenVisitedAfterTheCore) {
    // The mirror image: the core points come first in beam order.
    DbscanFilter f(params(1.0, 4));
    Scan scan = arcCanvas(20, 0.03);
    test::setRange(scan, 2, 5, 10.0);    // core
    test::setRange(scan, 8, 8, 10.0);    // border
    test::setRange(scan, 11, 11, 10.0);  // noise
    const auto r = f.filter(scan);
    EXPECT_EQ(r.clusters, 1u);
    EXPECT_EQ(r.points_removed, 1u);
    const auto& l = f.labels();
    EXPECT_GE(l[2], 0);
    for (const std::size_t i : {3, 4, 5, 8}) EXPECT_EQ(l[i], l[2]) << i;
    EXPECT_EQ(l[11], -1);
    EXPECT_EQ(validBeams(scan), (std::vector<std::size_t>{2, 3, 4, 5, 8}));
}

TEST(DbscanFilter, BorderBetweenTwoClustersJoinsOne) {
    // Same geometry: two core groups 1.8 m apart and one non-core point 0.9 m from each.
    // DBSCAN may put it in either cluster (Ester et al.: the first to reach it); it must stay.
    DbscanFilter f(params(1.0, 4));
    Scan scan = arcCanvas(20, 0.03);
    test::setRange(scan, 0, 3, 10.0);
    test::setRange(scan, 6, 6, 10.0);
    test::setRange(scan, 9, 12, 10.0);
    const auto r = f.filter(scan);
    EXPECT_EQ(r.clusters, 2u);
    EXPECT_EQ(r.points_removed, 0u);
    const auto& l = f.labels();
    for (const std::size_t i : {1, 2, 3}) EXPECT_EQ(l[i], l[0]) << i;
    for (const std::size_t i : {10, 11, 12}) EXPECT_EQ(l[i], l[9]) << i;
    EXPECT_GE(l[0], 0);
    EXPECT_GE(l[9], 0);
    EXPECT_NE(l[0], l[9]);
    EXPECT_TRUE(l[6] == l[0] || l[6] == l[9]) << l[6];
    EXPECT_EQ(scan.valid[6], 1);
}

TEST(DbscanFilter, MinPtsOneKeepsEveryPoint) {
    std::mt19937 rng(3);
    Scan scan = test::randomScan(rng, 360, test::deg2rad(270.0));
    const Scan input = scan;
    DbscanFilter f(params(0.05, 1));
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_removed, 0u);
    EXPECT_EQ(scan.valid, input.valid);
    EXPECT_GT(r.clusters, 10u);
    for (std::size_t i = 0; i < scan.size(); ++i)
        EXPECT_EQ(f.labels()[i] >= 0, input.valid[i] != 0) << i;
}

TEST(DbscanFilter, InvalidBeamsAreIgnored) {
    // The outlier at beam 90 would have 11 neighbours if the invalid beams 91..100 (same range)
    // were counted.
    DbscanFilter f;
    Scan scan = test::flatWall(181, test::deg2rad(90.0), 3.0);
    test::setRange(scan, 90, 100, 1.0);
    test::invalidate(scan, 91, 100);
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 171u);
    EXPECT_EQ(r.points_removed, 1u);
    EXPECT_EQ(r.clusters, 1u);
    EXPECT_EQ(scan.valid[90], 0);
    for (std::size_t i = 90; i <= 100; ++i) {
        EXPECT_EQ(f.labels()[i], -1) << i;
        EXPECT_EQ(scan.valid[i], 0) << i;
    }
    EXPECT_EQ(scan.countValid(), 170u);
}

TEST(DbscanFilter, EmptyScans) {
    DbscanFilter f;
    Scan none = test::emptyScan(50, kPi);
    auto r = f.filter(none);
    EXPECT_EQ(r.points_in, 0u);
    EXPECT_EQ(r.clusters, 0u);
    EXPECT_EQ(r.points_removed, 0u);
    EXPECT_EQ(f.labels(), std::vector<std::int32_t>(50, -1));
    Scan zero = test::makeScan({});
    r = f.filter(zero);
    EXPECT_EQ(r.points_in, 0u);
    EXPECT_TRUE(f.labels().empty());
    Scan one = test::makeScan({2.0f});  // a single point is noise for minPts > 1
    r = f.filter(one);
    EXPECT_EQ(r.points_removed, 1u);
    EXPECT_EQ(one.valid[0], 0);
}

TEST(DbscanFilter, LabelsDescribeTheLastScan) {
    DbscanFilter f(params(0.5, 4));
    auto [big, small] = test::largeThenSmallScans();
    Scan smallCopy = small;
    f.filter(big);
    const auto r = f.filter(small);
    DbscanFilter fresh(params(0.5, 4));
    const auto rf = fresh.filter(smallCopy);
    EXPECT_EQ(f.labels().size(), 90u);
    EXPECT_EQ(f.labels(), fresh.labels());
    EXPECT_EQ(small.valid, smallCopy.valid);
    EXPECT_EQ(r.points_in, rf.points_in);
    EXPECT_EQ(r.clusters, rf.clusters);
    EXPECT_EQ(r.points_removed, rf.points_removed);
}

// --- Against a plain O(n^2) DBSCAN ----------------------------------------------------------

// The valid beams as Cartesian points, converted exactly as DbscanFilter does, so that
// distances at Eps compare identically.
using test::cartesian;
using test::Points;

/// Textbook DBSCAN by exhaustive search. N(p) = {q : |p - q| <= Eps}, p itself included (in
/// float, squared distance against Eps^2 as KdTree2D does); p is core when |N(p)| >= minPts;
/// clusters are the connected components of the core points under "within Eps"; a non-core
/// point is a border point of every cluster owning a core point in N(p), and noise when there
/// is none.
struct Reference {
    std::vector<bool> core;
    std::vector<std::int32_t> component;                   // core points: cluster id; others -1
    std::vector<std::vector<std::size_t>> coreNeighbours;  // core points in N(p)
    std::size_t clusters = 0;
};

Reference plainDbscan(const Points& p, double eps_m, std::size_t min_pts) {
    const std::size_t m = p.x.size();
    const float eps = static_cast<float>(eps_m);
    const float eps2 = eps * eps;
    std::vector<std::vector<std::size_t>> nb(m);
    for (std::size_t i = 0; i < m; ++i)
        for (std::size_t j = 0; j < m; ++j) {
            const float dx = p.x[j] - p.x[i], dy = p.y[j] - p.y[i];
            if (dx * dx + dy * dy <= eps2) nb[i].push_back(j);
        }
    Reference ref;
    ref.core.assign(m, false);
    for (std::size_t i = 0; i < m; ++i) ref.core[i] = nb[i].size() >= min_pts;
    ref.component.assign(m, -1);
    for (std::size_t i = 0; i < m; ++i) {
        if (!ref.core[i] || ref.component[i] >= 0) continue;
        const auto id = static_cast<std::int32_t>(ref.clusters++);
        std::vector<std::size_t> stack{i};
        ref.component[i] = id;
        while (!stack.empty()) {
            const std::size_t q = stack.back();
            stack.pop_back();
            for (const std::size_t r : nb[q])
                if (ref.core[r] && ref.component[r] < 0) {
                    ref.component[r] = id;
                    stack.push_back(r);
                }
        }
    }
    ref.coreNeighbours.resize(m);
    for (std::size_t i = 0; i < m; ++i)
        for (const std::size_t j : nb[i])
            if (ref.core[j]) ref.coreNeighbours[i].push_back(j);
    return ref;
}

/// Compares DbscanFilter's output with the plain DBSCAN. Noise must match exactly and the
/// core points' partition must match up to label permutation. Border points reachable from
/// two clusters are TOLERATED, not avoided: DBSCAN gives them to whichever cluster reaches
/// them first, so a border point is accepted in the cluster of any of its core neighbours.
/// `ambiguous` counts those border points (to check the tolerant path is exercised).
::testing::AssertionResult matchesPlainDbscan(const Scan& input, const Scan& output,
                                              const DbscanFilter::Result& res,
                                              const std::vector<std::int32_t>& label,
                                              const DbscanFilter::Params& prm,
                                              std::size_t& ambiguous) {
    const Points pts = cartesian(input);
    const Reference ref = plainDbscan(pts, prm.eps_m, prm.min_pts);
    const std::size_t m = pts.x.size();
    if (label.size() != input.size())
        return ::testing::AssertionFailure() << "labels size " << label.size();
    if (output.range != input.range) return ::testing::AssertionFailure() << "ranges changed";
    for (std::size_t i = 0; i < input.size(); ++i)
        if (!input.valid[i] && (output.valid[i] || label[i] != -1))
            return ::testing::AssertionFailure() << "invalid beam " << i << " touched";
    if (res.points_in != m)
        return ::testing::AssertionFailure() << "points_in " << res.points_in << " vs " << m;

    std::size_t noise = 0;
    std::vector<std::int32_t> libCore, refCore;
    for (std::size_t k = 0; k < m; ++k) {
        const std::size_t b = pts.beam[k];
        const bool refNoise = ref.coreNeighbours[k].empty();
        const bool libNoise = output.valid[b] == 0;
        noise += refNoise;
        if (refNoise != libNoise)
            return ::testing::AssertionFailure()
                   << "beam " << b << ": reference says " << (refNoise ? "noise" : "not noise")
                   << " (core " << ref.core[k] << ", core neighbours "
                   << ref.coreNeighbours[k].size() << "), DbscanFilter "
                   << (libNoise ? "removed it" : "kept it");
        if (libNoise != (label[b] < 0))
            return ::testing::AssertionFailure() << "beam " << b << ": label " << label[b]
                                                 << " but valid " << int(output.valid[b]);
        if (ref.core[k]) {
            libCore.push_back(label[b]);
            refCore.push_back(ref.component[k]);
        } else if (!refNoise) {  // border point
            std::set<std::int32_t> allowed, components;
            for (const std::size_t c : ref.coreNeighbours[k]) {
                allowed.insert(label[pts.beam[c]]);
                components.insert(ref.component[c]);
            }
            ambiguous += components.size() > 1;
            if (!allowed.count(label[b]))
                return ::testing::AssertionFailure()
                       << "border beam " << b << " has label " << label[b]
                       << ", not that of any of its " << ref.coreNeighbours[k].size()
                       << " core neighbours";
        }
    }
    if (res.points_removed != noise)
        return ::testing::AssertionFailure()
               << "points_removed " << res.points_removed << " vs " << noise;
    if (res.clusters != ref.clusters)
        return ::testing::AssertionFailure()
               << "clusters " << res.clusters << " vs " << ref.clusters;
    if (!test::samePartition(libCore, refCore))
        return ::testing::AssertionFailure() << "core points partitioned differently";
    std::set<std::int32_t> used;
    for (const auto l : label)
        if (l >= 0) used.insert(l);
    if (used.size() != res.clusters)
        return ::testing::AssertionFailure()
               << used.size() << " distinct labels for " << res.clusters << " clusters";
    return ::testing::AssertionSuccess();
}

TEST(DbscanFilter, ReferenceAgreesWithHandMadeCase) {
    // Guards the reference the random comparison relies on.
    const Scan scan = borderScan(8);
    const Reference ref = plainDbscan(cartesian(scan), 1.0, 4);
    EXPECT_EQ(ref.core, (std::vector<bool>{false, false, true, true, true, true}));
    EXPECT_EQ(ref.clusters, 1u);
    EXPECT_TRUE(ref.coreNeighbours[0].empty());   // beam 2: noise
    EXPECT_EQ(ref.coreNeighbours[1].size(), 1u);  // beam 5: border
    EXPECT_EQ(ref.coreNeighbours[2].size(), 4u);  // beam 8: core
}

TEST(DbscanFilter, MatchesPlainDbscanOnRandomScans) {
    DbscanFilter f;  // one filter for every scan: buffers are reused across sizes
    std::size_t ambiguous = 0, removed = 0, multiCluster = 0;
    const int kScans = 300;
    for (int seed = 1; seed <= kScans; ++seed) {
        std::mt19937 rng(static_cast<unsigned>(seed));
        const std::size_t beams = std::uniform_int_distribution<std::size_t>(20, 720)(rng);
        const double aperture = test::randomAperture(rng, beams);
        DbscanFilter::Params p;  // every fourth scan with the paper's parameters
        if (seed % 4 != 0) {
            p.eps_m = std::uniform_real_distribution<double>(0.05, 1.5)(rng);
            p.min_pts = std::uniform_int_distribution<std::size_t>(1, 20)(rng);
        }
        f.initialize(p);
        const Scan input = test::randomScan(rng, beams, aperture);
        Scan output = input;
        const auto res = f.filter(output);
        ASSERT_TRUE(matchesPlainDbscan(input, output, res, f.labels(), p, ambiguous))
            << "seed " << seed << ", " << beams << " beams, Eps " << p.eps_m << ", minPts "
            << p.min_pts;
        removed += res.points_removed;
        multiCluster += res.clusters > 1;
    }
    // The comparison is not vacuous: noise, several clusters and ambiguous border points occur.
    EXPECT_GT(removed, 1000u);
    EXPECT_GT(multiCluster, static_cast<std::size_t>(kScans / 2));
    EXPECT_GT(ambiguous, 0u);
}

}  // namespace
}  // namespace kfd

namespace kfd {
namespace {

TEST(DbscanFilter, ValidBeamsWithoutAFiniteRangeAreNoise) {
    // Without the distance stage in front, a NaN or inf range flagged valid has no position;
    // it is removed instead of entering the k-d tree.
    Scan scan = test::emptyScan(181, kPi);
    test::setRange(scan, 40, 140, 2.0);
    scan.range[90] = std::numeric_limits<float>::quiet_NaN();
    scan.range[91] = std::numeric_limits<float>::infinity();
    DbscanFilter f;
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 101u);
    EXPECT_EQ(r.points_removed, 2u);
    EXPECT_FALSE(scan.valid[90]);
    EXPECT_FALSE(scan.valid[91]);
    EXPECT_TRUE(scan.valid[89]);
    EXPECT_TRUE(scan.valid[92]);
}

}  // namespace
}  // namespace kfd
