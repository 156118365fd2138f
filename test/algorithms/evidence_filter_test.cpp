// The evidence denoiser on tiny hand-made scans: what spatial and temporal evidence keep and
// remove, the noise estimate, the approximations against plain references, and bad parameters.
#include "kfd/algorithms/evidence_filter.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

using test::deg2rad;

// A room seen by a 361-beam, 180-degree scanner (0.5 deg): a wall 4 m ahead across the view.
Scan room(std::optional<Pose2D> odometry = Pose2D{}) {
    Scan s = test::flatWall(361, deg2rad(150.0), 4.0);
    s.odometry = odometry;
    return s;
}

// The same wall after the robot moved `dx` metres forward (odometry says so).
Scan roomAfter(double dx) {
    Scan s = test::flatWall(361, deg2rad(150.0), 4.0 - dx);
    s.odometry = Pose2D{dx, 0.0, 0.0};
    return s;
}

EvidenceFilter::Params exact() {
    EvidenceFilter::Params p;
    p.sigma_m = 0.01;  // noiseless test scans: fix the noise instead of estimating it
    return p;
}

TEST(EvidenceFilter, ASpikeInFrontOfAWallThePreviousKeyframeSawThroughIsRemoved) {
    EvidenceFilter f(exact());
    Clusters c;
    Scan first = room();
    f.filter(first, c);
    Scan second = roomAfter(0.1);
    test::insertSpike(second, 180, 3.6);  // 0.3 m in front of the wall, one beam
    const auto r = f.filter(second, c);
    EXPECT_TRUE(r.temporal);
    EXPECT_EQ(second.valid[180], 0);
    EXPECT_GE(r.free_points, 1u);
    EXPECT_EQ(r.points_removed, 1u);  // nothing else
}

EvidenceFilter::Params withSpikes(bool on) {
    EvidenceFilter::Params p = exact();
    p.spikes = on;
    return p;
}

TEST(EvidenceFilter, ASpikeCloseToItsWallIsRemovedByStep4bAlone) {
    // 0.15 m in front of the wall at 4 m: within the breakpoint distance, so one segment with
    // the wall, and no keyframe before it to see through it; only step 4b removes it.
    for (const bool on : {false, true}) {
        EvidenceFilter f(withSpikes(on));
        Clusters c;
        Scan s = room();
        test::insertSpike(s, 180, 3.85);
        const auto r = f.filter(s, c);
        EXPECT_EQ(s.valid[180], on ? 0 : 1);
        EXPECT_EQ(r.spikes, on ? 1u : 0u);
        EXPECT_EQ(r.points_removed, on ? 1u : 0u);
    }
}

TEST(EvidenceFilter, ASpikeThePreviousKeyframeSawIsAThinObjectAndStays) {
    // A pole 0.15 m in front of the wall, seen from both keyframes: supported, kept.
    EvidenceFilter f(withSpikes(true));
    Clusters c;
    Scan first = room();
    test::insertSpike(first, 180, 3.85);
    f.filter(first, c);
    Scan second = room();
    test::insertSpike(second, 180, 3.85);
    const auto r = f.filter(second, c);
    EXPECT_TRUE(r.temporal);
    EXPECT_EQ(second.valid[180], 1);
    EXPECT_EQ(r.spikes, 0u);
}

TEST(EvidenceFilter, AlternatingRangesAreClutterNotSpikes) {
    // A railing: 100 beams alternating between 4 m and 3.85 m, every one of them off both
    // neighbours; more than the bound (5 % of 361), so step 4b removes none of them.
    EvidenceFilter f(withSpikes(true));
    Clusters c;
    Scan s = room();
    for (std::size_t i = 130; i < 230; i += 2) test::insertSpike(s, i, 3.85);
    const auto r = f.filter(s, c);
    EXPECT_EQ(r.spikes, 0u);
    EvidenceFilter off(withSpikes(false));
    Scan t = room();
    for (std::size_t i = 130; i < 230; i += 2) test::insertSpike(t, i, 3.85);
    EXPECT_EQ(r.points_removed, off.filter(t, c).points_removed);
}

TEST(EvidenceFilter, ReturnsBetweenTheirNeighboursAreNoSpikes) {
    // A wall at grazing incidence: each range between its neighbours' (a ramp of 2 cm per
    // beam), nothing for step 4b.
    EvidenceFilter f(withSpikes(true));
    Clusters c;
    Scan s = room();
    for (std::size_t i = 150; i < 210; ++i)
        test::setRange(s, i, i, 2.0f + 0.02f * static_cast<float>(i - 150));
    const auto r = f.filter(s, c);
    EXPECT_EQ(r.spikes, 0u);
}

EvidenceFilter::Params withVeil(bool on) {
    EvidenceFilter::Params p = exact();
    p.veil = on;
    return p;
}

// A 181-beam, 180-degree scanner (1 deg): an object's edge at 2 m (beams 0-89), the wall
// behind it at 4 m (92-180), and two mixed pixels between them at 3.0 and 3.05 m (90, 91):
// one segment of two returns, too large at 3 m to be small on a 1-degree scanner.
Scan edgeWithMixedPixels() {
    Scan s = test::arc(181, kPi, 4.0);
    test::setRange(s, 0, 89, 2.0);
    test::setRange(s, 90, 90, 3.0);
    test::setRange(s, 91, 91, 3.05);
    return s;
}

TEST(EvidenceFilter, MixedPixelsBetweenANearAndAFarSurfaceAreRemovedByStep6Alone) {
    for (const bool on : {false, true}) {
        EvidenceFilter f(withVeil(on));
        Clusters c;
        Scan s = edgeWithMixedPixels();
        const auto r = f.filter(s, c);
        EXPECT_EQ(r.veils, on ? 2u : 0u) << on;
        EXPECT_EQ(s.valid[90], on ? 0 : 1) << on;
        EXPECT_EQ(s.valid[91], on ? 0 : 1) << on;
        EXPECT_EQ(r.points_removed, on ? 2u : 0u) << on;
    }
}

TEST(EvidenceFilter, MixedPixelsStayWhenTheyWouldTakeTheScanPastTheBound) {
    // Eight one-beam spikes at 1 m in the wall are small segments step 4 removes: 8 of the
    // bound's 9 (5 % of 181). The two mixed pixels would make 10: step 6 removes none.
    EvidenceFilter f(withVeil(true));
    Clusters c;
    Scan s = edgeWithMixedPixels();
    for (std::size_t i = 110; i < 150; i += 5) test::insertSpike(s, i, 1.0);
    const auto r = f.filter(s, c);
    EXPECT_EQ(r.veils, 0u);
    EXPECT_EQ(s.valid[90], 1);
    EXPECT_EQ(s.valid[91], 1);
    EXPECT_EQ(r.points_removed, 8u);
}

// Step 7 off: the tests of the burst logic below use flat bursts (constant range), which step 7
// would keep as surfaces.
EvidenceFilter::Params noSurfaces(EvidenceFilter::Params p) {
    p.keep_surfaces = false;
    return p;
}

TEST(EvidenceFilter, ABurstInFreeSpaceIsRemovedThoughItLooksLikeAnObject) {
    EvidenceFilter f(noSurfaces(exact()));
    Clusters c;
    Scan first = room();
    f.filter(first, c);
    Scan second = roomAfter(0.1);
    test::setRange(second, 170, 185, 1.0);  // 16 beams at 1 m: a flat "object"
    f.filter(second, c);
    for (std::size_t i = 170; i <= 185; ++i) EXPECT_EQ(second.valid[i], 0) << i;
    EXPECT_EQ(second.countValid(), first.countValid() - 16);
}

TEST(EvidenceFilter, ARunOnALineIsKeptWhateverTheTemporalEvidenceSays) {
    // The same 16 beams at 1 m (a line: a wall seen from a new viewpoint) are kept by step 7;
    // 16 beams scattered +-6 cm about 1 m (far off any line at sigma = 1 cm) still go.
    for (const bool scattered : {false, true}) {
        EvidenceFilter f(exact());
        Clusters c;
        Scan first = room();
        f.filter(first, c);
        Scan second = roomAfter(0.1);
        for (std::size_t i = 170; i <= 185; ++i)
            test::setRange(second, i, i, scattered ? (i % 2 ? 1.06f : 0.94f) : 1.0f);
        const auto r = f.filter(second, c);
        for (std::size_t i = 170; i <= 185; ++i) EXPECT_EQ(second.valid[i], scattered ? 0 : 1) << i;
        EXPECT_EQ(r.surface_kept, scattered ? 0u : 16u);
        EXPECT_EQ(r.points_removed, scattered ? 16u : 0u);
    }
}

TEST(EvidenceFilter, APersistentThinObjectIsKept) {
    // A chair leg (one beam at 2 m) seen by two keyframes in a row: spatially a lone return, but
    // the previous keyframe saw it at the same place.
    EvidenceFilter f(exact());
    Clusters c;
    Scan first = room();
    test::insertSpike(first, 200, 2.0);
    f.filter(first, c);
    Scan second = room();  // the robot stands still
    test::insertSpike(second, 200, 2.0);
    const auto r = f.filter(second, c);
    EXPECT_EQ(second.valid[200], 1);
    EXPECT_EQ(r.points_removed, 0u);
}

TEST(EvidenceFilter, ReferencesThatContradictTooMuchOfAScanAreStale) {
    // The keyframe saw a wall at 4 m; odometry says the robot did not move, but the scan shows
    // a wall at 2 m across the whole view (odometry that lied, a turn): every return lies in
    // space the keyframe saw through. That is stale references, not noise (issue 22).
    EvidenceFilter f(exact());
    Clusters c;
    Scan first = room();
    f.filter(first, c);
    Scan second = test::flatWall(361, deg2rad(150.0), 2.0);
    second.odometry = Pose2D{};
    const auto r = f.filter(second, c);
    EXPECT_TRUE(r.stale_references);
    EXPECT_FALSE(r.capped);
    EXPECT_GT(r.removal_wanted, 300u);
    EXPECT_EQ(r.points_removed, 0u);  // spatially one wall: nothing small
    EXPECT_EQ(second.countValid(), 361u);
}

TEST(EvidenceFilter, RemovalIsCappedSmallestSegmentsFirst) {
    // 30 lone returns and one pair, all small and unsupported (no keyframe yet): 32 returns,
    // above 5 % of 361 (18). The 18 lone returns of the nearest ranges go, nothing else.
    EvidenceFilter f(exact());
    Clusters c;
    Scan s = room(std::nullopt);
    for (std::size_t k = 0; k < 30; ++k) test::insertSpike(s, 15 + 10 * k, 1.5 + 0.01 * k);
    test::setRange(s, 330, 331, 1.0);
    const auto r = f.filter(s, c);
    EXPECT_FALSE(r.stale_references);
    EXPECT_TRUE(r.capped);
    EXPECT_EQ(r.removal_wanted, 32u);
    EXPECT_EQ(r.points_removed, 18u);
    EXPECT_EQ(s.valid[330], 1);
    EXPECT_EQ(s.valid[331], 1);
    for (std::size_t k = 0; k < 30; ++k)
        EXPECT_EQ(s.valid[15 + 10 * k], k < 18 ? 0 : 1) << k;  // the nearest 18
}

TEST(EvidenceFilter, NoBoundRemovesEverySmallSegment) {
    EvidenceFilter::Params p = exact();
    p.max_removed_fraction = 1.0;
    EvidenceFilter f(p);
    Clusters c;
    Scan s = room(std::nullopt);
    for (std::size_t k = 0; k < 30; ++k) test::insertSpike(s, 15 + 10 * k, 1.5 + 0.01 * k);
    const auto r = f.filter(s, c);
    EXPECT_FALSE(r.capped);
    EXPECT_EQ(r.points_removed, 30u);
}

TEST(EvidenceFilter, WithoutAPreviousKeyframeOnlyLoneReturnsAreRemoved) {
    EvidenceFilter f(exact());
    Clusters c;
    Scan s = room(std::nullopt);
    test::insertSpike(s, 100, 1.5);    // alone
    test::setRange(s, 250, 259, 1.0);  // ten beams at 1 m: an object
    const auto r = f.filter(s, c);
    EXPECT_FALSE(r.temporal);
    EXPECT_EQ(s.valid[100], 0);
    for (std::size_t i = 250; i <= 259; ++i) EXPECT_EQ(s.valid[i], 1) << i;
    EXPECT_EQ(r.points_removed, 1u);
}

TEST(EvidenceFilter, APairOfReturnsBetweenDropoutsIsASurfaceNotASmallSegment) {
    // No keyframe yet: only small segments go. Two wall returns amid 18 dropouts (a dark patch
    // of the wall) stay with dropout_fragments; a pair 2 m before the wall, flanked by its
    // returns, and a lone return amid dropouts go either way.
    for (const bool on : {true, false}) {
        EvidenceFilter::Params p = exact();
        p.dropout_fragments = on;
        EvidenceFilter f(p);
        Clusters c;
        Scan s = room(std::nullopt);
        for (std::size_t i = 196; i <= 213; ++i) s.valid[i] = i == 204 || i == 205 ? 1 : 0;
        test::setRange(s, 100, 101, 2.0);
        for (std::size_t i = 296; i <= 304; ++i) s.valid[i] = i == 300 ? 1 : 0;
        f.filter(s, c);
        EXPECT_EQ(s.valid[204], on ? 1 : 0) << on;
        EXPECT_EQ(s.valid[205], on ? 1 : 0) << on;
        EXPECT_EQ(s.valid[100], 0) << on;
        EXPECT_EQ(s.valid[101], 0) << on;
        EXPECT_EQ(s.valid[300], 0) << on;
    }
}

TEST(EvidenceFilter, AWallAtGrazingIncidenceStaysOneSegment) {
    // A wall 0.5 m to the side running along the view: consecutive returns are far apart and
    // nearly along the beam (the breakpoint cuts it), but they lie on a line.
    Scan s = test::emptyScan(361, deg2rad(180.0));
    for (std::size_t i = 10; i < 100; ++i) {
        const double a = s.geometry.angle(i);  // -90 .. -45 deg: the right side
        s.range[i] = static_cast<float>(0.5 / std::abs(std::sin(a)));
        s.valid[i] = 1;
    }
    EvidenceFilter f(exact());
    Clusters c;
    const auto r = f.filter(s, c);
    EXPECT_EQ(r.points_removed, 0u);
    EXPECT_EQ(c.count(), 1u);
}

// A corner (a wall 4 m ahead, one 1.5 m to the right) seen from (x, 0), heading forward.
Scan corner(double x) {
    Scan s = test::emptyScan(361, deg2rad(180.0));
    for (std::size_t i = 0; i < s.size(); ++i) {
        const double a = s.geometry.angle(i), c = std::cos(a), sn = std::sin(a);
        double r = c > 1e-9 ? (4.0 - x) / c : 1e9;
        if (sn < -1e-9) r = std::min(r, 1.5 / -sn);
        if (r < 10.0) test::setRange(s, i, i, r);
    }
    return s;
}

TEST(EvidenceFilter, WithoutOdometryTheStepIsFoundByAlignment) {
    // Laser only: the robot moved 0.15 m; the scans are aligned from zero motion.
    EvidenceFilter f(exact());
    Clusters c;
    Scan first = corner(0.0);
    f.filter(first, c);
    Scan second = corner(0.15);
    test::insertSpike(second, 200, 2.5);
    const auto r = f.filter(second, c);
    EXPECT_TRUE(r.temporal);
    EXPECT_TRUE(r.refined);
    EXPECT_EQ(second.valid[200], 0);
    EXPECT_EQ(r.points_removed, 1u);
}

EvidenceFilter::Params withRecent(std::size_t scans) {
    EvidenceFilter::Params p = exact();
    p.temporal_scans = scans;
    return p;
}

TEST(EvidenceFilter, ASpikeNearAWallIsRemovedWithTheScanJustBeforeTheKeyframe) {
    // The keyframe 1 m back supports a spike 0.12 m in front of the wall (its margin is
    // 0.04 + 0.05 + 0.2 x 1 m); the scan dropped 2 cm before sees through it.
    for (const std::size_t kept : {0u, 1u}) {
        EvidenceFilter f(withRecent(kept));
        Clusters c;
        Scan first = room();
        f.filter(first, c);
        f.observe(roomAfter(0.98));
        Scan second = roomAfter(1.0);
        test::insertSpike(second, 180, 2.88f);
        const auto r = f.filter(second, c);
        EXPECT_TRUE(r.temporal);
        EXPECT_EQ(r.recent, kept > 0);
        if (kept == 0) {
            // The keyframe saw a smooth wall there: that supports the wall, not the spike.
            EXPECT_EQ(second.valid[180], 0);
            EXPECT_EQ(r.spikes, 1u);
        } else {
            EXPECT_EQ(second.valid[180], 0);
            EXPECT_EQ(r.points_removed, 1u);
            EXPECT_NEAR(r.recent_margin_m, 3.0 * std::sqrt(2.0) * 0.01, 1e-6);  // sigma-bound
        }
    }
}

TEST(EvidenceFilter, ASpikeTheKeyframeSawAsAnObjectTooIsKept) {
    // The same spike 0.12 m before the wall, without the scan just before: kept where the
    // keyframe 1 m back saw a return off its own wall there (a thin object seen twice), and,
    // with spike_object_support off, where it saw only the wall within its wide margin.
    for (const bool object : {false, true}) {
        for (const bool object_support : {false, true}) {
            EvidenceFilter::Params p = withRecent(0);
            p.spike_object_support = object_support;
            EvidenceFilter f(p);
            Clusters c;
            Scan first = room();
            if (object) test::insertSpike(first, 180, 3.88);
            f.filter(first, c);
            Scan second = roomAfter(1.0);
            test::insertSpike(second, 180, 2.88f);
            const auto r = f.filter(second, c);
            EXPECT_TRUE(r.temporal);
            const bool kept = object || !object_support;
            EXPECT_EQ(second.valid[180], kept ? 1 : 0) << object << object_support;
            EXPECT_EQ(r.points_removed, kept ? 0u : 1u) << object << object_support;
        }
    }
}

TEST(EvidenceFilter, WhenTheScanJustBeforeWantsTooMuchTheKeyframesAloneDecide) {
    // 20 beams 0.3 m before the wall: the scan 2 cm before sees through them, the keyframe
    // 1 m back supports them. 20 returns exceed a 5 % bound (18 of 361): without the burst
    // exception (max_confirmed_fraction = 0) the keyframes decide.
    for (const double bound : {0.05, 1.0}) {
        EvidenceFilter::Params p = noSurfaces(withRecent(1));
        p.max_removed_fraction = bound;
        p.max_confirmed_fraction = 0.0;
        EvidenceFilter f(p);
        Clusters c;
        Scan first = room();
        f.filter(first, c);
        f.observe(roomAfter(0.98));
        Scan second = roomAfter(1.0);
        test::setRange(second, 170, 189, 2.7);
        const auto r = f.filter(second, c);
        EXPECT_TRUE(r.recent);
        EXPECT_EQ(r.recent_overruled, bound < 1.0) << bound;
        EXPECT_FALSE(r.stale_references);
        EXPECT_FALSE(r.confirmed);
        EXPECT_EQ(r.points_removed, bound < 1.0 ? 0u : 20u) << bound;
    }
}

// The keyframe room(), then the scan `before` dropped, then `key` filtered (with `after` as
// its next scan when given).
EvidenceFilter::Result keyframeAfter(const EvidenceFilter::Params& p, const Scan& before, Scan& key,
                                     const Scan* after = nullptr) {
    EvidenceFilter f(p);
    Clusters c;
    Scan start = room();
    f.filter(start, c);
    f.observe(before);
    return f.filter(key, c, after);
}

// The keyframe 1 m back, the scan dropped 2 cm before the next keyframe (`recent`), and that
// keyframe with a burst of beams [first, last] 0.3 m in front of the wall.
EvidenceFilter::Result burstAfter(const EvidenceFilter::Params& p, const Scan& recent,
                                  std::size_t first, std::size_t last, Scan& out) {
    out = roomAfter(1.0);
    test::setRange(out, first, last, 2.7);
    return keyframeAfter(p, recent, out);
}

TEST(EvidenceFilter, ABurstAboveTheBoundIsRemovedWholeWhenTheScanJustBeforeConfirmsIt) {
    // The same 20-beam burst (5.5 % of the returns, above the 5 % bound): the scan just before
    // supports every other return it judged, so the burst is what changed, not the references.
    Scan second;
    const auto r = burstAfter(noSurfaces(withRecent(1)), roomAfter(0.98), 170, 189, second);
    EXPECT_TRUE(r.recent);
    EXPECT_TRUE(r.confirmed);
    EXPECT_FALSE(r.recent_overruled);
    EXPECT_FALSE(r.stale_references);
    EXPECT_FALSE(r.capped);
    EXPECT_EQ(r.removal_wanted, 20u);
    EXPECT_EQ(r.points_removed, 20u);
    for (std::size_t i = 170; i <= 189; ++i) EXPECT_EQ(second.valid[i], 0) << i;
}

TEST(EvidenceFilter, ABurstIsNotConfirmedWhenTheScanJustBeforeDisagreesElsewhere) {
    // The scan just before saw a recess 1.2 m deep over beams 100-159 (beyond the alignment's
    // gate, so the alignment holds) that this scan does not: 15 of the 88 wall returns it
    // judged are free (83 % supported). With confirm_support 0.9 it is not trusted beyond the
    // bound and the keyframes decide (their margin supports the burst); asking half confirms.
    Scan recent = roomAfter(0.98);
    test::setWall(recent, 100, 159, 4.0 - 0.98 + 1.2);
    for (const double support : {0.9, 0.5}) {
        EvidenceFilter::Params p = noSurfaces(withRecent(1));
        p.confirm_support = support;
        Scan second;
        const auto r = burstAfter(p, recent, 170, 189, second);
        EXPECT_TRUE(r.recent);
        EXPECT_EQ(r.confirmed, support < 0.9) << support;
        EXPECT_EQ(r.recent_overruled, support >= 0.9) << support;
        EXPECT_EQ(r.points_removed, support < 0.9 ? 20u : 0u) << support;
    }
}

TEST(EvidenceFilter, ABurstAboveTheConfirmedBoundIsNotRemovedWhole) {
    // 100 beams (28 % of the returns) exceed max_confirmed_fraction (25 %): the references
    // are taken as stale even though the scan just before agrees with the rest.
    Scan second;
    const auto r = burstAfter(withRecent(1), roomAfter(0.98), 130, 229, second);
    EXPECT_FALSE(r.confirmed);
    EXPECT_LE(r.points_removed, 18u);  // the 5 % bound
    EXPECT_EQ(second.valid[180], 1);
}

TEST(EvidenceFilter, AThinPostSeenJustBeforeIsKept) {
    // A two-beam post at 2 m (small) in front of the wall: the scan just before saw it too.
    auto withPost = [](Scan s) {
        test::setRange(s, 180, 181, 2.0);
        return s;
    };
    EvidenceFilter f(withRecent(1));
    Clusters c;
    Scan first = room();
    f.filter(first, c);
    f.observe(withPost(roomAfter(0.08)));
    Scan second = withPost(roomAfter(0.1));
    const auto r = f.filter(second, c);
    EXPECT_TRUE(r.recent);
    EXPECT_EQ(second.valid[180], 1);
    EXPECT_EQ(second.valid[181], 1);
    EXPECT_EQ(r.points_removed, 0u);
}

TEST(EvidenceFilter, WithoutOdometryTheScanJustBeforeIsAligned) {
    EvidenceFilter f(withRecent(2));
    Clusters c;
    Scan first = corner(0.0);
    f.filter(first, c);
    f.observe(corner(0.13));
    f.observe(corner(0.14));
    Scan second = corner(0.15);
    test::insertSpike(second, 200, 2.5);
    const auto r = f.filter(second, c);
    EXPECT_TRUE(r.recent);
    EXPECT_EQ(second.valid[200], 0);
    EXPECT_EQ(r.points_removed, 1u);
}

// Issue 39, item 2 (track_alignment): where the track stage placed the scans, its poses align
// them.
EvidenceFilter::Tracked trackedAt(double x, double rms_m = 0.01) {
    return EvidenceFilter::Tracked{Pose2D{x, 0.0, 0.0}, rms_m};
}

EvidenceFilter::Params trackAligned(EvidenceFilter::Params p) {
    p.track_alignment = true;
    return p;
}

TEST(EvidenceFilter, WhereTheTrackerPlacedBothKeyframesItsPosesReplaceOdometryAndAlignment) {
    // The robot moved 0.1 m; the odometry says 0.6 m (a slip): the tracker's poses are used as
    // they are and the denoiser runs no alignment of its own.
    for (const bool use_track : {true, false}) {
        EvidenceFilter::Params p = exact();
        p.track_alignment = use_track;
        EvidenceFilter f(p);
        Clusters c;
        Scan first = room();
        const auto t0 = trackedAt(0.0), t1 = trackedAt(0.1);
        f.filter(first, c, nullptr, &t0);
        Scan second = test::flatWall(361, deg2rad(150.0), 3.9);
        second.odometry = Pose2D{0.6, 0.0, 0.0};
        test::insertSpike(second, 180, 3.5);
        const auto r = f.filter(second, c, nullptr, &t1);
        EXPECT_TRUE(r.temporal);
        EXPECT_EQ(r.refined, !use_track);
        if (use_track) {
            EXPECT_EQ(second.valid[180], 0);
            EXPECT_EQ(r.points_removed, 1u);
        }
    }
}

// A keyframe 1 m on from the one before, the raw scan just before it 2 cm back, all three
// tracked (the raw scan's fit 0.02 m RMS), a spike 0.12 m in front of the wall.
struct TrackedRawScan {
    Scan second = roomAfter(1.0);
    EvidenceFilter::Result r;
};

TrackedRawScan filterWithATrackedRawScan(const EvidenceFilter::Params& p) {
    EvidenceFilter f(p);
    Clusters c;
    Scan first = room();
    const auto t0 = trackedAt(0.0), tb = trackedAt(0.98, 0.02), t1 = trackedAt(1.0, 0.015);
    f.filter(first, c, nullptr, &t0);
    f.observe(roomAfter(0.98), &tb);
    TrackedRawScan out;
    test::insertSpike(out.second, 180, 2.88f);
    out.r = f.filter(out.second, c, nullptr, &t1);
    return out;
}

TEST(EvidenceFilter, TheRawScanJustBeforeIsPlacedByTheTrackerWithItsResidualAsTheMargin) {
    const auto [second, r] = filterWithATrackedRawScan(trackAligned(withRecent(1)));
    EXPECT_TRUE(r.recent);
    EXPECT_FALSE(r.refined);
    EXPECT_NEAR(r.recent_margin_m, 3.0 * 0.02, 1e-9);  // 3 x the larger residual of the two
    EXPECT_EQ(second.valid[180], 0);
    EXPECT_EQ(r.points_removed, 1u);
}

TEST(EvidenceFilter, TrackRawAlignmentPlacesTheRawScanByTheTrackerAndAlignsTheKeyframeItself) {
    // On (the default): the scan just before takes the tracker's step and residual margin, the
    // keyframe before is aligned by the denoiser from odometry. Off: the raw scan is aligned
    // by the denoiser too, its margin 3 sqrt(2) sigma (its alignment's residuals are zero).
    for (const bool raw : {true, false}) {
        EvidenceFilter::Params p = withRecent(1);
        p.track_raw_alignment = raw;
        const auto [second, r] = filterWithATrackedRawScan(p);
        EXPECT_TRUE(r.recent);
        EXPECT_TRUE(r.refined);
        EXPECT_NEAR(r.recent_margin_m, raw ? 3.0 * 0.02 : 3.0 * std::sqrt(2.0) * 0.01, 1e-6);
        EXPECT_EQ(second.valid[180], 0);
        EXPECT_EQ(r.points_removed, 1u);
    }
}

// A chair leg (one beam) 2 m ahead in a keyframe; the next keyframe 0.1 m on, both tracked
// there; the odometry slipped (it says 1.5 m, beyond the alignment's 1 m first gate).
struct SlippedKeyframe {
    Scan second = test::flatWall(361, deg2rad(150.0), 3.9);
    EvidenceFilter::Result r;
};

SlippedKeyframe filterASlippedKeyframe(const EvidenceFilter::Params& p) {
    EvidenceFilter f(p);
    Clusters c;
    Scan first = room();
    test::insertSpike(first, 180, 2.0);
    const auto t0 = trackedAt(0.0), t1 = trackedAt(0.1);
    f.filter(first, c, nullptr, &t0);
    SlippedKeyframe out;
    out.second.odometry = Pose2D{1.5, 0.0, 0.0};
    test::insertSpike(out.second, 180, 1.9);
    out.r = f.filter(out.second, c, nullptr, &t1);
    return out;
}

TEST(EvidenceFilter, TrackKeyframeStartAlignsTheKeyframeFromTheTrackersStepNotOdometry) {
    // On: the denoiser's own alignment starts from the tracker's 0.1 m and runs its last
    // step; the keyframe before saw the leg there: kept. Off (the default): it starts from the
    // slipped odometry, no return pairs within the gate, the step stays wrong and the leg,
    // supported by nothing, goes as a lone return.
    for (const bool start : {true, false}) {
        EvidenceFilter::Params p = withRecent(0);  // the keyframes alone: no raw scan before
        p.track_keyframe_start = start;
        const auto [second, r] = filterASlippedKeyframe(p);
        EXPECT_TRUE(r.temporal);
        EXPECT_EQ(r.refined, start);
        EXPECT_EQ(second.valid[180], start ? 1 : 0);
    }
}

TEST(EvidenceFilter, WithNoTrackedRefineIterationsTheTrackersStepIsUsedAsItIs) {
    EvidenceFilter::Params p = withRecent(0);
    p.track_keyframe_start = true;
    p.tracked_refine_iterations = 0;
    const auto [second, r] = filterASlippedKeyframe(p);
    EXPECT_FALSE(r.refined);
    EXPECT_EQ(second.valid[180], 1);
}

TEST(EvidenceFilter, WithoutOdometryTheTrackersStepStartsTheAlignment) {
    // Laser only, the sensor 1.2 m on (a walking sensor between keyframes), the leg 2 m from
    // where the keyframe before was. Tracked (by default, track_keyframe_start off): the
    // alignment starts from the tracker's step and the leg is supported. Not tracked: from
    // zero motion it finds no pairs and the keyframe's beam seems to pass through the leg.
    for (const bool tracked : {true, false}) {
        EvidenceFilter f(withRecent(0));
        Clusters c;
        Scan first = room(std::nullopt);
        test::insertSpike(first, 180, 2.0);
        const auto t0 = trackedAt(0.0), t1 = trackedAt(1.2);
        f.filter(first, c, nullptr, tracked ? &t0 : nullptr);
        Scan second = test::flatWall(361, deg2rad(150.0), 2.8);
        test::insertSpike(second, 180, 0.8);
        const auto r = f.filter(second, c, nullptr, tracked ? &t1 : nullptr);
        EXPECT_EQ(r.refined, tracked);
        EXPECT_EQ(second.valid[180], tracked ? 1 : 0);
    }
}

TEST(EvidenceFilter, AReferenceTheTrackerDidNotPlaceIsAlignedByTheDenoiser) {
    // The keyframe before was not tracked (the first scan, a lost track): odometry and the
    // denoiser's own alignment place it, as without a tracker.
    EvidenceFilter f(trackAligned(exact()));
    Clusters c;
    Scan first = room();
    f.filter(first, c);
    Scan second = roomAfter(0.1);
    test::insertSpike(second, 180, 3.6);
    const auto t1 = trackedAt(0.1);
    const auto r = f.filter(second, c, nullptr, &t1);
    EXPECT_TRUE(r.temporal);
    EXPECT_TRUE(r.refined);
    EXPECT_EQ(second.valid[180], 0);
}

TEST(EvidenceFilter, TheKeyframeItselfIsTheScanBeforeTheNextWhenNothingWasDropped) {
    EvidenceFilter f(withRecent(1));
    Clusters c;
    Scan first = room();
    EXPECT_FALSE(f.filter(first, c).recent);  // nothing before the first scan
    Scan second = roomAfter(0.02);
    EXPECT_TRUE(f.filter(second, c).recent);
    f.reset();
    Scan third = roomAfter(0.04);
    EXPECT_FALSE(f.filter(third, c).recent);  // reset forgets the raw scans too
}

EvidenceFilter::Params withNext(bool next) {
    EvidenceFilter::Params p = withRecent(1);
    p.next_scan = next;
    return p;
}

TEST(EvidenceFilter, ABurstOnlyInTheKeyframeIsRemovedWithTheScanJustAfter) {
    // A 5-beam burst 0.28 m in front of the wall in the keyframe only. The scan just before
    // has dropouts there (no verdict); the keyframe 1 m back supports the burst (its wide
    // margin). Without the next scan it stays; the scan 2 cm after sees through it.
    for (const bool next : {false, true}) {
        Scan before = roomAfter(0.98);
        for (std::size_t i = 175; i <= 185; ++i) before.valid[i] = 0;
        Scan key = roomAfter(1.0);
        test::setRange(key, 178, 182, 2.72f);  // its own segment (0.19 m breakpoint)
        const Scan after = roomAfter(1.02);
        const auto r = keyframeAfter(noSurfaces(withNext(next)), before, key, &after);
        EXPECT_TRUE(r.recent);
        EXPECT_EQ(r.next, next);
        for (std::size_t i = 178; i <= 182; ++i) EXPECT_EQ(key.valid[i], next ? 0 : 1) << i;
        EXPECT_EQ(r.points_removed, next ? 5u : 0u);
    }
}

TEST(EvidenceFilter, ASurfaceThatAppearsInTheKeyframeAndStaysInTheNextScanIsKept) {
    // 12 beams at 2 m (a door swung open, a person stepping in): the keyframe and the scan
    // just after see it, the scan just before and the keyframe before saw the wall through
    // it. Without the next scan it goes as free space (step 7 off; on, it is a line and stays);
    // with it, its support keeps it.
    auto withSurface = [](Scan s) {
        test::setRange(s, 175, 186, 2.0f);
        return s;
    };
    for (const bool next : {false, true}) {
        Scan key = withSurface(roomAfter(1.0));
        const Scan after = withSurface(roomAfter(1.02));
        const auto r = keyframeAfter(noSurfaces(withNext(next)), roomAfter(0.98), key, &after);
        EXPECT_TRUE(r.recent);
        EXPECT_EQ(r.next, next);
        for (std::size_t i = 175; i <= 186; ++i) EXPECT_EQ(key.valid[i], next ? 1 : 0) << i;
        EXPECT_EQ(r.points_removed, next ? 0u : 12u);
    }
}

TEST(EvidenceFilter, WithoutANextScanTheKeyframeIsFilteredAsWithoutTheOption) {
    // The end of a log: no scan after the keyframe. next = nullptr gives what next_scan =
    // false gives; and a next scan is ignored when the option is off.
    EvidenceFilter on(withNext(true)), off(withNext(false));
    Clusters c;
    Scan a = room(), b = room();
    on.filter(a, c);
    off.filter(b, c);
    Scan x = roomAfter(1.0), y = roomAfter(1.0), z = roomAfter(1.0);
    test::setRange(x, 178, 182, 2.88f);
    test::setRange(y, 178, 182, 2.88f);
    test::insertSpike(x, 100, 1.5f);
    test::insertSpike(y, 100, 1.5f);
    const auto rx = on.filter(x, c, nullptr);
    const auto ry = off.filter(y, c, &z);
    EXPECT_FALSE(rx.next);
    EXPECT_FALSE(ry.next);
    EXPECT_EQ(x.valid, y.valid);
    EXPECT_EQ(rx.points_removed, ry.points_removed);
}

TEST(EvidenceFilter, ObservingDoesNothingWithoutTemporalScans) {
    // temporal_scans = 0 keeps today's behaviour: an observed scan changes no result.
    EvidenceFilter a(withRecent(0)), b(withRecent(0));
    Clusters c;
    Scan first = room(), first_b = room();
    a.filter(first, c);
    b.filter(first_b, c);
    Scan seen = roomAfter(0.98);
    test::insertSpike(seen, 100, 1.0);
    b.observe(seen);
    Scan x = roomAfter(1.0), y = roomAfter(1.0);
    test::insertSpike(x, 180, 2.88f);
    test::insertSpike(y, 180, 2.88f);
    const auto ra = a.filter(x, c), rb = b.filter(y, c);
    EXPECT_EQ(ra.points_removed, rb.points_removed);
    EXPECT_EQ(ra.supported, rb.supported);
    EXPECT_EQ(x.valid, y.valid);
    EXPECT_FALSE(rb.recent);
}

TEST(EvidenceFilter, ARawScanOfAnotherGeometryIsNotUsed) {
    EvidenceFilter f(withRecent(1));
    Clusters c;
    Scan first = room();
    f.filter(first, c);
    Scan other = test::flatWall(181, deg2rad(150.0), 3.0);
    other.odometry = Pose2D{0.98, 0.0, 0.0};
    f.observe(other);
    Scan second = roomAfter(1.0);
    EXPECT_FALSE(f.filter(second, c).recent);
}

TEST(EvidenceFilter, TheNoiseEstimateFollowsTheSensor) {
    std::mt19937 rng(7);
    for (const double sigma : {0.01, 0.03}) {
        EvidenceFilter f;  // estimated
        Clusters c;
        std::normal_distribution<double> noise(0.0, sigma);
        double last = 0.0;
        for (int k = 0; k < 20; ++k) {
            Scan s = test::flatWall(1081, deg2rad(150.0), 3.0);
            for (auto& r : s.range) r = static_cast<float>(r + noise(rng));
            last = f.filter(s, c).sigma;
        }
        EXPECT_NEAR(last, sigma, 0.35 * sigma) << sigma;
    }
}

TEST(EvidenceFilter, ResetForgetsThePreviousKeyframe) {
    EvidenceFilter f(exact());
    Clusters c;
    Scan first = room();
    f.filter(first, c);
    f.reset();
    Scan second = roomAfter(0.1);
    EXPECT_FALSE(f.filter(second, c).temporal);
}

TEST(EvidenceFilter, AnotherGeometryGivesNoTemporalEvidence) {
    EvidenceFilter f(exact());
    Clusters c;
    Scan first = room();
    f.filter(first, c);
    Scan other = test::flatWall(181, deg2rad(150.0), 4.0);
    other.odometry = Pose2D{};
    EXPECT_FALSE(f.filter(other, c).temporal);
}

TEST(EvidenceFilter, ApproxAtan2MatchesStdAtan2) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-50.0f, 50.0f);
    double worst = 0.0;
    for (int k = 0; k < 200000; ++k) {
        const float y = u(rng), x = u(rng);
        worst =
            std::max(worst, std::abs(static_cast<double>(EvidenceFilter::approxAtan2(y, x)) -
                                     std::atan2(static_cast<double>(y), static_cast<double>(x))));
    }
    EXPECT_LT(worst, 2e-5);  // a 0.25-degree beam is 4.4e-3 rad
    EXPECT_EQ(EvidenceFilter::approxAtan2(0.0f, 0.0f), 0.0f);
}

TEST(EvidenceFilter, LineResidualIsZeroOnAnyLine) {
    // Three beams 0.5 deg apart hitting a line at any incidence: the middle one is predicted.
    const double res = deg2rad(0.5);
    for (const double incidence : {0.0, 40.0, 80.0, 88.0}) {
        const double a = deg2rad(incidence);
        auto r = [&](double theta) { return 2.0 * std::cos(a) / std::cos(theta - a); };
        EXPECT_NEAR(EvidenceFilter::lineResidual(r(-res), r(0.0), r(res), std::cos(res)), 0.0, 1e-9)
            << incidence;
    }
}

TEST(EvidenceFilter, TooManyTemporalScansAreRejected) {
    EvidenceFilter::Params p;
    p.temporal_scans = 17;
    EXPECT_THROW(EvidenceFilter{p}, ParameterError);
    p.temporal_scans = 16;
    EXPECT_NO_THROW(EvidenceFilter{p});
}

TEST(EvidenceFilter, BadParametersAreRejected) {
    auto bad = [](auto change) {
        EvidenceFilter::Params p;
        change(p);
        EXPECT_THROW(EvidenceFilter{p}, ParameterError);
    };
    bad([](auto& p) { p.incidence_deg = 0.0; });
    bad([](auto& p) { p.incidence_deg = 90.0; });
    bad([](auto& p) { p.sigma_m = -1.0; });
    bad([](auto& p) { p.sigma_m = std::nan(""); });
    bad([](auto& p) { p.min_sigma_m = 0.0; });
    bad([](auto& p) { p.max_gap_beams = 17; });
    bad([](auto& p) { p.pose_rot_error_deg = -1.0; });
    bad([](auto& p) { p.moving_object_m = std::numeric_limits<double>::infinity(); });
    bad([](auto& p) { p.max_step_m = 0.0; });
    bad([](auto& p) { p.refine_samples = 0; });
    bad([](auto& p) { p.tracked_refine_iterations = 4; });  // more than refine_iterations (3)
    bad([](auto& p) { p.tracked_refine_samples = 0; });
    bad([](auto& p) { p.tracked_refine_samples = 129; });  // more than refine_samples (128)
    bad([](auto& p) { p.max_removed_fraction = 0.0; });
    bad([](auto& p) { p.max_removed_fraction = 1.5; });
    bad([](auto& p) { p.max_confirmed_fraction = -0.1; });
    bad([](auto& p) { p.max_confirmed_fraction = 1.1; });
    bad([](auto& p) { p.confirm_support = 0.0; });
    bad([](auto& p) { p.surface_min_beams = 1; });
    bad([](auto& p) { p.surface_sigmas = -1.0; });
    bad([](auto& p) { p.surface_sigmas = std::nan(""); });
}

TEST(EvidenceFilter, DegenerateScansAreHandled) {
    EvidenceFilter f;
    Clusters c;
    Scan empty = test::emptyScan(361, kPi);
    EXPECT_EQ(f.filter(empty, c).points_removed, 0u);
    Scan two = test::makeScan({1.0f, 1.0f}, kPi);
    f.filter(two, c);
    Scan circle = test::circle(720, 3.0);  // closes the circle: one segment across the seam
    circle.odometry = Pose2D{};
    f.filter(circle, c);
    EXPECT_EQ(c.count(), 1u);
    EXPECT_EQ(circle.countValid(), 720u);
}

}  // namespace
}  // namespace kfd
