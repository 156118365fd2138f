#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/algorithms/view_keyframe_selector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/paper/correlation.h"
#include "kfd/paper/histogram.h"
#include "test_scans.h"

namespace kfd {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kBins = 6;

/// Selector with every guard off: decisions follow Formula 3 alone.
KeyframeSelector::Params paperParams(std::size_t window, double p_pair) {
    KeyframeSelector::Params p;
    p.bins = kBins;
    p.window = window;
    p.p_pair = p_pair;
    p.max_consecutive_drops = 0;
    p.max_interval_s = 0.0;
    p.max_translation_m = 0.0;
    p.max_rotation_deg = 0.0;
    return p;
}

/// Histograms with a controlled Pearson correlation: 5 m + cu*U + cv*V + cw*W with U, V, W
/// zero-mean orthonormal columns, so pearson(hist(a), hist(b)) = cos of the angle between
/// the coefficient vectors a and b.
std::vector<double> hist(double cu, double cv, double cw = 0.0) {
    const double su = 1.0 / std::sqrt(2.0), sv = 1.0 / std::sqrt(6.0), sw = 1.0 / std::sqrt(12.0);
    const double U[kBins] = {su, -su, 0, 0, 0, 0};
    const double V[kBins] = {sv, sv, -2 * sv, 0, 0, 0};
    const double W[kBins] = {sw, sw, sw, -3 * sw, 0, 0};
    std::vector<double> h(kBins);
    for (std::size_t i = 0; i < kBins; ++i) h[i] = 5.0 + cu * U[i] + cv * V[i] + cw * W[i];
    return h;
}
/// Unit coefficient vector at angle a (rad) in the U-V plane.
std::vector<double> histAt(double a) { return hist(std::cos(a), std::sin(a)); }

double corr(const std::vector<double>& a, const std::vector<double>& b) {
    return pearson(a.data(), b.data(), a.size());
}

KeyframeDecision decide(KeyframeSelector& s, const std::vector<double>& h, double stamp = kNaN,
                        const std::optional<Pose2D>& odo = std::nullopt) {
    return s.decide(h, stamp, odo);
}

Pose2D pose(double x, double y, double phi_deg) { return Pose2D{x, y, test::deg2rad(phi_deg)}; }

TEST(KeyframeSelector, HistogramHelperHasTheIntendedCorrelation) {
    // Guards the construction the other tests rely on.
    EXPECT_NEAR(corr(histAt(0.0), histAt(std::acos(0.8))), 0.8, 1e-12);
    EXPECT_NEAR(corr(hist(1, 0), hist(0, 1)), 0.0, 1e-12);
    EXPECT_NEAR(corr(hist(1, 0), hist(-1, 0)), -1.0, 1e-12);
    EXPECT_NEAR(corr(hist(0.6, 0.0, 0.8), hist(1, 0)), 0.6, 1e-12);
}

TEST(KeyframeSelector, FirstScanIsKeyframe) {
    KeyframeSelector s(paperParams(8, 0.985));
    EXPECT_EQ(s.windowSize(), 0u);
    const auto d = decide(s, histAt(0.0));
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::First);
    EXPECT_EQ(d.references, 0u);
    EXPECT_EQ(d.consecutive_drops, 0u);
    EXPECT_EQ(s.windowSize(), 1u);
}

TEST(KeyframeSelector, IdenticalScansAreDropped) {
    KeyframeSelector::Params p;  // the paper's rule with its default parameters, scans
    // without time or odometry
    KeyframeSelector s(p);
    const Scan scan = test::flatWall(181, test::deg2rad(120.0), 3.0);
    EXPECT_EQ(s.filter(scan).reason, KeyframeReason::First);
    for (std::size_t k = 1; k <= 5; ++k) {
        const auto d = s.filter(scan);
        EXPECT_FALSE(d.keyframe);
        EXPECT_EQ(d.reason, KeyframeReason::Similar);
        EXPECT_NEAR(d.p_common, 1.0, 1e-12);
        EXPECT_EQ(d.references, 1u);
        EXPECT_EQ(d.consecutive_drops, k);
    }
    EXPECT_EQ(s.windowSize(), 1u);  // drops never enter the window
}

TEST(KeyframeSelector, DissimilarScanIsKeyframe) {
    KeyframeSelector s(paperParams(8, 0.985));
    decide(s, histAt(0.0));
    const auto d = decide(s, histAt(kPi / 2));  // uncorrelated
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::Dissimilar);
    EXPECT_NEAR(d.p_common, 0.0, 1e-12);
    EXPECT_EQ(s.windowSize(), 2u);
}

TEST(KeyframeSelector, ScanThatSuddenlySeesNothingIsKeyframe) {
    KeyframeSelector::Params p;
    KeyframeSelector s(p);
    Scan scan = test::flatWall(181, test::deg2rad(120.0), 3.0);
    s.filter(scan);
    test::invalidate(scan, 0, scan.size() - 1);
    const auto d = s.filter(scan);
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::Dissimilar);
}

TEST(KeyframeSelector, FilterUsesTheScanHistogram) {
    KeyframeSelector::Params p;
    p.bins = 4;
    KeyframeSelector s(p);
    const Scan scan = test::makeScan({1, 1, 2, 2, 3, 3, 4, 4});
    const Scan copy = scan;
    s.filter(scan);
    EXPECT_EQ(s.lastHistogram(), (std::vector<double>{1, 2, 3, 4}));
    EXPECT_EQ(scan.valid, copy.valid);  // the scan is not modified
    EXPECT_EQ(scan.range, copy.range);
    // The same histogram fed through decide() is recognised as similar.
    EXPECT_EQ(s.decide({1, 2, 3, 4}, kNaN, std::nullopt).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, PCommonIsTheProductOverTheWindow) {
    KeyframeSelector s(paperParams(4, 0.999));
    std::mt19937 rng(42);
    std::normal_distribution<double> noise(0.0, 0.6);
    const std::vector<double> base{1, 4, 2, 6, 3, 5};
    auto noisy = [&] {
        std::vector<double> h = base;
        for (auto& x : h) x += noise(rng);
        return h;
    };
    std::vector<std::vector<double>> keyframes;
    while (keyframes.size() < 4) {
        const auto h = noisy();
        if (decide(s, h).keyframe) keyframes.push_back(h);
    }
    ASSERT_EQ(s.windowSize(), 4u);
    for (int trial = 0; trial < 20; ++trial) {
        const auto target = noisy();
        double product = 1.0, weakest = 1.0;
        for (const auto& k : keyframes) {
            const double c = std::max(0.0, corr(target, k));
            product *= c;
            weakest = std::min(weakest, c);
        }
        ASSERT_GT(product, 0.0);  // the product must be informative
        ASSERT_LT(product, 0.999);
        const auto d = decide(s, target);
        EXPECT_NEAR(d.p_common, product, 1e-12);
        EXPECT_NEAR(d.min_similarity, weakest, 1e-12);
        EXPECT_EQ(d.references, 4u);
        EXPECT_NEAR(d.p_threshold, 0.999 * 0.999 * 0.999 * 0.999, 1e-15);
        EXPECT_EQ(d.keyframe, product < d.p_threshold);
        if (d.keyframe) {  // the window slides: keep the mirror up to date
            keyframes.erase(keyframes.begin());
            keyframes.push_back(target);
        }
    }
}

TEST(KeyframeSelector, ThresholdUsesReferencesSoFar) {
    // m = 8 but only k keyframes so far: the threshold is P_pair^k, not P_pair^m.
    KeyframeSelector s(paperParams(8, 0.9));
    decide(s, histAt(0.0));
    // Similarity 0.5 >= 0.9^8 = 0.43 would drop it; against 0.9^1 it is new information.
    auto d = decide(s, histAt(kPi / 3));
    EXPECT_EQ(d.references, 1u);
    EXPECT_DOUBLE_EQ(d.p_threshold, 0.9);
    EXPECT_NEAR(d.p_common, 0.5, 1e-12);
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::Dissimilar);
    // Halfway between the two: 0.866^2 = 0.75 < 0.9^2 = 0.81.
    d = decide(s, histAt(kPi / 6));
    EXPECT_EQ(d.references, 2u);
    EXPECT_NEAR(d.p_threshold, 0.81, 1e-15);
    EXPECT_NEAR(d.p_common, 0.75, 1e-12);
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(s.windowSize(), 3u);
}

TEST(KeyframeSelector, JustAboveThresholdIsDropped) {
    KeyframeSelector s(paperParams(8, 0.985));
    decide(s, histAt(0.0));
    const auto d = decide(s, histAt(std::acos(0.985 + 1e-6)));
    EXPECT_FALSE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::Similar);
    EXPECT_NEAR(d.p_common, 0.985 + 1e-6, 1e-12);
}

TEST(KeyframeSelector, JustBelowThresholdIsKeyframe) {
    KeyframeSelector s(paperParams(8, 0.985));
    decide(s, histAt(0.0));
    const auto d = decide(s, histAt(std::acos(0.985 - 1e-6)));
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::Dissimilar);
}

TEST(KeyframeSelector, ThresholdAcrossTwoReferences) {
    // K1, K2 at +-6 degrees (correlation cos 12deg = 0.978 < 0.985, so K2 is a keyframe).
    // A target tilted out of their plane by beta correlates cos(beta)*cos(6deg) with each,
    // so P_common = (cos(beta)*cos(6deg))^2 against P_pair^2.
    const double delta = test::deg2rad(6.0);
    for (const double eps : {1e-6, -1e-6}) {
        KeyframeSelector s(paperParams(8, 0.985));
        decide(s, histAt(-delta));
        ASSERT_TRUE(decide(s, histAt(delta)).keyframe);
        const double cb = (0.985 + eps) / std::cos(delta);
        const auto d = decide(s, hist(cb, 0.0, std::sqrt(1.0 - cb * cb)));
        EXPECT_EQ(d.references, 2u);
        EXPECT_NEAR(d.p_common, (0.985 + eps) * (0.985 + eps), 1e-12);
        EXPECT_EQ(d.keyframe, eps < 0) << "eps " << eps;
    }
}

TEST(KeyframeSelector, PCommonEqualToThresholdIsDropped) {
    // P_pair = 1: only a perfectly correlated scan (pearson exactly 1 here: the deviations
    // are halves, so every sum is exact) reaches P_common >= P_pair^k.
    KeyframeSelector s(paperParams(8, 1.0));
    const std::vector<double> h{1, 2, 3, 4, 5, 6};
    decide(s, h);
    ASSERT_EQ(corr(h, h), 1.0);
    const auto same = decide(s, {2, 4, 6, 8, 10, 12});  // same shape, twice the range
    EXPECT_EQ(same.p_common, 1.0);
    EXPECT_EQ(same.reason, KeyframeReason::Similar);
    EXPECT_TRUE(decide(s, {1, 2, 3, 4, 5, 6.01}).keyframe);
}

TEST(KeyframeSelector, NegativeCorrelationsNeverYieldADrop) {
    KeyframeSelector s(paperParams(2, 0.95));
    const auto k1 = hist(1.0, 0.0);
    const auto k2 = hist(0.94, std::sqrt(1.0 - 0.94 * 0.94));  // similarity 0.94 < 0.95
    decide(s, k1);
    ASSERT_TRUE(decide(s, k2).keyframe);
    // The mirror image of K1: pearson -1 with K1 and -0.94 with K2. Unclamped, the product
    // would be 0.94 >= 0.95^2 = 0.9025, i.e. "similar".
    const auto target = hist(-1.0, 0.0);
    ASSERT_NEAR(corr(target, k1) * corr(target, k2), 0.94, 1e-12);
    const auto d = decide(s, target);
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::Dissimilar);
    EXPECT_EQ(d.p_common, 0.0);
    EXPECT_EQ(d.min_similarity, 0.0);
}

TEST(KeyframeSelector, WindowEvictsTheOldestKeyframe) {
    // Keyframes at 0, a and 2a in the U-V plane (cos a = 0.8); the target sits at 1.5a: close
    // to the two latest (cos 0.5a = 0.949 each) but far from the first (cos 1.5a = 0.569).
    const double a = std::acos(0.8);
    auto run = [&](std::size_t window) {
        KeyframeSelector s(paperParams(window, 0.9));
        EXPECT_TRUE(decide(s, histAt(0.0)).keyframe);
        EXPECT_TRUE(decide(s, histAt(a)).keyframe);      // 0.8 < 0.9
        EXPECT_TRUE(decide(s, histAt(2 * a)).keyframe);  // 0.28 * 0.8 < 0.81
        EXPECT_EQ(s.windowSize(), std::min<std::size_t>(window, 3));
        return decide(s, histAt(1.5 * a));
    };
    // m = 2: the first keyframe has left the window; 0.9 >= 0.81 -> dropped.
    const auto evicted = run(2);
    EXPECT_EQ(evicted.references, 2u);
    EXPECT_NEAR(evicted.p_common, 0.9, 1e-12);
    EXPECT_FALSE(evicted.keyframe);
    // m = 3: the first keyframe still counts; 0.9 * 0.569 < 0.729 -> keyframe.
    const auto kept = run(3);
    EXPECT_EQ(kept.references, 3u);
    EXPECT_TRUE(kept.keyframe);
}

TEST(KeyframeSelector, WindowSizeSaturatesAtM) {
    KeyframeSelector s(paperParams(3, 0.5));
    for (int k = 0; k < 6; ++k) {
        // Alternate orthogonal and opposite histograms: every one is dissimilar.
        const auto d = decide(s, histAt(k * kPi / 2));
        EXPECT_TRUE(d.keyframe) << k;
        EXPECT_EQ(d.references, static_cast<std::size_t>(std::min(k, 3))) << k;
    }
    EXPECT_EQ(s.windowSize(), 3u);
}

TEST(KeyframeSelector, MaxConsecutiveDropsForcesKeyframe) {
    auto p = paperParams(8, 0.985);
    p.max_consecutive_drops = 3;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h);
    for (std::size_t k = 1; k <= 3; ++k) {
        const auto d = decide(s, h);
        EXPECT_EQ(d.reason, KeyframeReason::Similar) << k;
        EXPECT_EQ(d.consecutive_drops, k);
    }
    const auto forced = decide(s, h);
    EXPECT_TRUE(forced.keyframe);
    EXPECT_EQ(forced.reason, KeyframeReason::MaxDrops);
    EXPECT_EQ(forced.consecutive_drops, 0u);
    // The count starts again after the forced keyframe.
    const auto next = decide(s, h);
    EXPECT_EQ(next.reason, KeyframeReason::Similar);
    EXPECT_EQ(next.consecutive_drops, 1u);
}

TEST(KeyframeSelector, MaxConsecutiveDropsOffWhenZero) {
    KeyframeSelector s(paperParams(8, 0.985));
    const auto h = histAt(0.0);
    decide(s, h);
    for (int k = 0; k < 200; ++k) ASSERT_EQ(decide(s, h).reason, KeyframeReason::Similar) << k;
}

TEST(KeyframeSelector, DissimilarKeyframeResetsTheDropCount) {
    auto p = paperParams(1, 0.985);
    p.max_consecutive_drops = 3;
    KeyframeSelector s(p);
    decide(s, histAt(0.0));
    decide(s, histAt(0.0));
    decide(s, histAt(0.0));
    EXPECT_EQ(decide(s, histAt(kPi / 2)).reason, KeyframeReason::Dissimilar);
    EXPECT_EQ(decide(s, histAt(kPi / 2)).consecutive_drops, 1u);
    EXPECT_EQ(decide(s, histAt(kPi / 2)).consecutive_drops, 2u);
    EXPECT_EQ(decide(s, histAt(kPi / 2)).consecutive_drops, 3u);
    EXPECT_EQ(decide(s, histAt(kPi / 2)).reason, KeyframeReason::MaxDrops);
}

TEST(KeyframeSelector, MaxIntervalForcesKeyframe) {
    auto p = paperParams(8, 0.985);
    p.max_interval_s = 2.0;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h, 10.0);
    EXPECT_EQ(decide(s, h, 11.0).reason, KeyframeReason::Similar);
    EXPECT_EQ(decide(s, h, 11.99).reason, KeyframeReason::Similar);
    const auto d = decide(s, h, 12.0);  // exactly T after the last keyframe
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::MaxInterval);
    // Measured from the new keyframe.
    EXPECT_EQ(decide(s, h, 13.5).reason, KeyframeReason::Similar);
    EXPECT_EQ(decide(s, h, 14.0).reason, KeyframeReason::MaxInterval);
}

TEST(KeyframeSelector, MaxIntervalIgnoresUnknownTimestamps) {
    auto p = paperParams(8, 0.985);
    p.max_interval_s = 2.0;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h, kNaN);
    EXPECT_EQ(decide(s, h, 100.0).reason, KeyframeReason::Similar);  // no reference time yet
    EXPECT_EQ(decide(s, h, kNaN).reason, KeyframeReason::Similar);
    // Stamps from a dropped scan are not a reference either.
    EXPECT_EQ(decide(s, h, 1000.0).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, MaxIntervalOffWhenZero) {
    KeyframeSelector s(paperParams(8, 0.985));
    const auto h = histAt(0.0);
    decide(s, h, 0.0);
    EXPECT_EQ(decide(s, h, 1e6).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, TranslationForcesKeyframe) {
    auto p = paperParams(8, 0.985);
    p.max_translation_m = 0.625;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h, kNaN, pose(1.0, 2.0, 30.0));
    EXPECT_EQ(decide(s, h, kNaN, pose(1.3, 2.4, 30.0)).reason, KeyframeReason::Similar);  // 0.5
    const auto d = decide(s, h, kNaN, pose(1.375, 2.5, 30.0));  // exactly 0.625 m
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::Translation);
    // Measured from the new keyframe.
    EXPECT_EQ(decide(s, h, kNaN, pose(1.375, 3.0, 30.0)).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, TranslationAccumulatesOverDrops) {
    auto p = paperParams(8, 0.985);
    p.max_translation_m = 0.5;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h, kNaN, pose(0.0, 0.0, 0.0));
    EXPECT_EQ(decide(s, h, kNaN, pose(-0.2, 0.0, 0.0)).reason, KeyframeReason::Similar);
    EXPECT_EQ(decide(s, h, kNaN, pose(-0.4, 0.0, 0.0)).reason, KeyframeReason::Similar);
    EXPECT_EQ(decide(s, h, kNaN, pose(-0.6, 0.0, 0.0)).reason, KeyframeReason::Translation);
}

TEST(KeyframeSelector, TranslationNeedsOdometry) {
    auto p = paperParams(8, 0.985);
    p.max_translation_m = 0.5;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h);  // first keyframe without odometry: no reference pose
    EXPECT_EQ(decide(s, h, kNaN, pose(5.0, 0.0, 0.0)).reason, KeyframeReason::Similar);
    EXPECT_EQ(decide(s, h, kNaN, pose(9.0, 0.0, 0.0)).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, TranslationOffWhenZero) {
    KeyframeSelector s(paperParams(8, 0.985));
    const auto h = histAt(0.0);
    decide(s, h, kNaN, pose(0.0, 0.0, 0.0));
    EXPECT_EQ(decide(s, h, kNaN, pose(100.0, -50.0, 0.0)).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, RotationInPlaceProducesKeyframes) {
    // A 360-degree scanner turning on the spot in a round room sees the same scan every time;
    // only the rotation guard makes keyframes.
    KeyframeSelector::Params p;  // defaults: A = 15 deg, D = 0.5 m
    p.max_interval_s = 0.0;
    KeyframeSelector s(p);
    Scan scan = test::circle(360, 4.0);
    std::vector<KeyframeReason> reasons;
    for (int k = 0; k <= 12; ++k) {
        scan.odometry = pose(2.0, 3.0, 6.0 * k);  // 6 deg per scan, zero translation
        reasons.push_back(s.filter(scan).reason);
    }
    const auto R = KeyframeReason::Rotation, S = KeyframeReason::Similar;
    EXPECT_EQ(reasons, (std::vector<KeyframeReason>{KeyframeReason::First, S, S, R, S, S, R, S, S,
                                                    R, S, S, R}));
}

TEST(KeyframeSelector, RotationFiresAtThreshold) {
    auto p = paperParams(8, 0.985);
    p.max_rotation_deg = 15.0;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h, kNaN, pose(0, 0, 0.0));
    EXPECT_EQ(decide(s, h, kNaN, pose(0, 0, -14.9)).reason, KeyframeReason::Similar);
    EXPECT_EQ(decide(s, h, kNaN, pose(0, 0, -15.1)).reason, KeyframeReason::Rotation);
}

TEST(KeyframeSelector, RotationWrapsAroundPi) {
    auto p = paperParams(8, 0.985);
    p.max_rotation_deg = 15.0;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h, kNaN, pose(0, 0, 175.0));
    // -175 deg is 10 deg further on, not 350 deg back.
    EXPECT_EQ(decide(s, h, kNaN, pose(0, 0, -175.0)).reason, KeyframeReason::Similar);
    EXPECT_EQ(decide(s, h, kNaN, pose(0, 0, -165.0)).reason, KeyframeReason::Rotation);
    // A full turn is no turn.
    EXPECT_EQ(decide(s, h, kNaN, pose(0, 0, -165.0 + 360.0)).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, RotationOffWhenZero) {
    KeyframeSelector s(paperParams(8, 0.985));
    const auto h = histAt(0.0);
    decide(s, h, kNaN, pose(0, 0, 0.0));
    EXPECT_EQ(decide(s, h, kNaN, pose(0, 0, 90.0)).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, GuardsDoNotRelabelDissimilarScans) {
    auto p = paperParams(8, 0.985);
    p.max_translation_m = 0.5;
    p.max_rotation_deg = 15.0;
    p.max_interval_s = 1.0;
    KeyframeSelector s(p);
    decide(s, histAt(0.0), 0.0, pose(0, 0, 0));
    const auto d = decide(s, histAt(kPi / 2), 10.0, pose(10, 0, 90));
    EXPECT_EQ(d.reason, KeyframeReason::Dissimilar);
}

TEST(KeyframeSelector, ResetForgetsTheWindow) {
    KeyframeSelector s(paperParams(8, 0.985));
    decide(s, histAt(0.0));
    decide(s, histAt(kPi / 3));
    ASSERT_EQ(s.windowSize(), 2u);
    s.reset();
    EXPECT_EQ(s.windowSize(), 0u);
    const auto first = decide(s, histAt(kPi / 2));
    EXPECT_EQ(first.reason, KeyframeReason::First);
    EXPECT_EQ(first.references, 0u);
    // Only the new keyframe is compared: the old ones (similarity 0 and 0.87) are gone.
    const auto d = decide(s, histAt(kPi / 2));
    EXPECT_EQ(d.reason, KeyframeReason::Similar);
    EXPECT_EQ(d.references, 1u);
    EXPECT_NEAR(d.p_common, 1.0, 1e-12);
}

TEST(KeyframeSelector, ResetForgetsReferencePoseAndTime) {
    auto p = paperParams(8, 0.985);
    p.max_translation_m = 0.5;
    p.max_interval_s = 1.0;
    KeyframeSelector s(p);
    const auto h = histAt(0.0);
    decide(s, h, 0.0, pose(0, 0, 0));
    s.reset();
    decide(s, h, kNaN);  // First, without time or pose
    EXPECT_EQ(decide(s, h, 50.0, pose(20, 0, 0)).reason, KeyframeReason::Similar);
}

TEST(KeyframeSelector, RejectsBadParams) {
    const KeyframeSelector::Params good;
    auto bad = [&](auto mutate) {
        KeyframeSelector::Params p = good;
        mutate(p);
        EXPECT_THROW(KeyframeSelector{p}, kfd::ParameterError);
    };
    bad([](auto& p) { p.bins = 1; });
    bad([](auto& p) { p.bins = 0; });
    bad([](auto& p) { p.window = 0; });
    bad([](auto& p) { p.p_pair = 0.0; });
    bad([](auto& p) { p.p_pair = -0.5; });
    bad([](auto& p) { p.p_pair = 1.0001; });
    bad([](auto& p) { p.p_pair = kNaN; });
    bad([](auto& p) { p.max_interval_s = -1.0; });
    bad([](auto& p) { p.max_interval_s = kNaN; });
    bad([](auto& p) { p.max_translation_m = -0.1; });
    bad([](auto& p) { p.max_rotation_deg = -1.0; });
    bad([](auto& p) { p.max_rotation_deg = kNaN; });
    KeyframeSelector::Params edge = good;
    edge.bins = 2;
    edge.window = 1;
    edge.p_pair = 1.0;
    EXPECT_NO_THROW(KeyframeSelector{edge});
}

TEST(KeyframeSelector, RejectsHistogramOfWrongSize) {
    KeyframeSelector s(paperParams(8, 0.985));
    EXPECT_THROW(s.decide(std::vector<double>(kBins + 1, 1.0), kNaN, std::nullopt),
                 kfd::ParameterError);
    EXPECT_THROW(s.decide({}, kNaN, std::nullopt), kfd::ParameterError);
}

TEST(KeyframeSelector, ReasonNames) {
    EXPECT_EQ(std::string(toString(KeyframeReason::First)), "first");
    EXPECT_EQ(std::string(toString(KeyframeReason::Dissimilar)), "dissimilar");
    EXPECT_EQ(std::string(toString(KeyframeReason::MaxDrops)), "max_drops");
    EXPECT_EQ(std::string(toString(KeyframeReason::MaxInterval)), "max_interval");
    EXPECT_EQ(std::string(toString(KeyframeReason::Translation)), "translation");
    EXPECT_EQ(std::string(toString(KeyframeReason::Rotation)), "rotation");
    EXPECT_EQ(std::string(toString(KeyframeReason::Similar)), "similar");
    EXPECT_EQ(std::string(toString(KeyframeReason::ViewChange)), "view_change");
    EXPECT_EQ(std::string(toString(KeyframeReason::Corridor)), "corridor");
    EXPECT_EQ(std::string(toString(KeyframeReason::Covered)), "covered");
}

// kfd's rule is a selector of its own (the view_keyframe stage's): the paper's class never
// measures a view, and the view selector never builds a histogram.
TEST(ViewKeyframeSelector, TheSameViewWithoutOdometryIsCovered) {
    ViewKeyframeSelector s;
    const Scan scan = test::flatWall(181, test::deg2rad(120.0), 3.0);
    EXPECT_EQ(s.filter(scan).reason, KeyframeReason::First);
    const auto d = s.filter(scan);  // the same view, no odometry: covered
    EXPECT_FALSE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::Covered);
    EXPECT_EQ(d.changed_fraction, 0.0);
}

TEST(ViewKeyframeSelector, GuardsForceAKeyframeOnACoveredView) {
    ViewKeyframeSelector::Params p;
    p.max_consecutive_drops = 2;
    ViewKeyframeSelector s(p);
    const Scan scan = test::flatWall(181, test::deg2rad(120.0), 3.0);
    s.filter(scan);
    EXPECT_FALSE(s.filter(scan).keyframe);
    EXPECT_FALSE(s.filter(scan).keyframe);
    const auto d = s.filter(scan);
    EXPECT_TRUE(d.keyframe);
    EXPECT_EQ(d.reason, KeyframeReason::MaxDrops);
}

TEST(KeyframeSelector, ThePapersRuleMeasuresNoView) {
    KeyframeSelector s;
    const Scan scan = test::flatWall(181, test::deg2rad(120.0), 3.0);
    s.filter(scan);
    const auto d = s.filter(scan);
    EXPECT_EQ(d.reason, KeyframeReason::Similar);
    EXPECT_EQ(d.view_change, 0.0);
    EXPECT_GT(d.p_common, 0.99);
}

}  // namespace
}  // namespace kfd
