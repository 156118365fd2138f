#include "kfd/algorithms/view_selector.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/algorithms/pose.h"
#include "kfd/algorithms/view_keyframe_selector.h"
#include "test_scans.h"

namespace kfd {
namespace {

using test::Segment;

/// A scan taken at `pose` in a world of segments (test::castScan).
Scan cast(const std::vector<Segment>& world, const Pose2D& pose, std::size_t beams = 361,
          double aperture = kPi) {
    return test::castScan(world, pose, beams, aperture);
}

std::vector<Segment> room(double half) {
    return {{-half, -half, half, -half},
            {half, -half, half, half},
            {half, half, -half, half},
            {-half, half, -half, -half}};
}
std::vector<Segment> corridor(double half_width, double length) {
    return {{-length, -half_width, length, -half_width}, {-length, half_width, length, half_width}};
}

/// The view change from its definition: the translation |t| in units of a, plus the RMS over
/// the sampled points (robot frame) of the rotation's displacement |(R - I) p| in units of
/// a + r tan(b), added in quadrature.
double plainViewChange(const Scan& s, const Pose2D& rel, const ViewSelector::Params& p) {
    const std::size_t k = (s.size() + p.max_samples - 1) / p.max_samples;
    const double tb = std::tan(p.tolerance_deg * kPi / 180.0);
    double num = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.size(); i += k) {
        if (!s.valid[i]) continue;
        const double r = s.range[i], a = s.geometry.angle(i);
        const Pose2D pt = compose(s.sensor_pose, Pose2D{r * std::cos(a), r * std::sin(a), 0.0});
        const Pose2D turned = compose(Pose2D{0.0, 0.0, rel.phi}, pt);
        const double d = std::hypot(turned.x - pt.x, turned.y - pt.y) / (p.tolerance_m + tb * r);
        num += d * d;
        ++n;
    }
    const double t2 = (rel.x * rel.x + rel.y * rel.y) / (p.tolerance_m * p.tolerance_m);
    return std::sqrt(t2 + num / static_cast<double>(n));
}

TEST(ViewSelector, FirstScanIsAKeyframeAndTheSameViewIsCovered) {
    ViewSelector v;
    const Scan s = cast(room(3.0), Pose2D{0.5, 0.2, 0.1});
    EXPECT_TRUE(v.measure(s).keyframe);
    v.accept(s);
    const ViewMeasure m = v.measure(s);
    EXPECT_FALSE(m.keyframe);
    EXPECT_TRUE(m.used_odometry);
    EXPECT_NEAR(m.view_change, 0.0, 1e-6);
    EXPECT_FALSE(m.corridor);
}

TEST(ViewSelector, ClosedFormViewChangeEqualsThePlainDefinition) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    ViewSelector::Params p;
    p.max_samples = 97;
    for (int trial = 0; trial < 200; ++trial) {
        Scan s = test::randomScan(rng, 181 + static_cast<std::size_t>(trial) * 3,
                                  test::randomAperture(rng, 361));
        s.sensor_pose = Pose2D{0.3 * u(rng), 0.2 * u(rng), 0.5 * u(rng)};
        const Pose2D kf{u(rng), u(rng), kPi * u(rng)};
        const Pose2D rel{0.4 * u(rng), 0.4 * u(rng), 0.5 * u(rng)};
        ViewSelector v(p);
        Scan first = s;
        first.odometry = kf;
        v.measure(first);
        v.accept(first);
        s.odometry = compose(kf, rel);
        const ViewMeasure m = v.measure(s);
        if (s.countValid() == 0) continue;
        EXPECT_NEAR(m.view_change, plainViewChange(s, rel, p), 1e-4 + 1e-4 * m.view_change)
            << trial;
    }
}

TEST(ViewSelector, TranslationCountsAlikeEverywhereRotationCountsMoreInAWideHall) {
    auto change = [&](double half, const Pose2D& step) {
        ViewSelector s;
        const Scan a = cast(room(half), Pose2D{});
        s.measure(a);
        s.accept(a);
        return s.measure(cast(room(half), step)).view_change;
    };
    const Pose2D forward{0.2, 0.0, 0.0}, turn{0.0, 0.0, test::deg2rad(5.0)};
    EXPECT_NEAR(change(1.0, forward), change(12.0, forward), 1e-6);
    EXPECT_NEAR(change(1.0, forward), 0.2 / 0.3, 1e-6);  // |t| / a
    EXPECT_GT(change(12.0, turn), 2.0 * change(1.0, turn));
}

TEST(ViewSelector, KeyframeWhenTheViewChangeReachesTheThreshold) {
    ViewSelector v;
    const Scan a = cast(room(3.0), Pose2D{});
    v.measure(a);
    v.accept(a);
    std::size_t first_keyframe = 0;
    for (std::size_t k = 1; k <= 40 && first_keyframe == 0; ++k) {
        const ViewMeasure m = v.measure(cast(room(3.0), Pose2D{0.02 * k, 0.0, 0.0}));
        if (m.keyframe) {
            EXPECT_GE(m.view_change, v.params().max_view_change);
            first_keyframe = k;
        } else {
            EXPECT_LT(m.view_change, v.params().max_view_change);
        }
    }
    EXPECT_GT(first_keyframe, 3u);   // 2 cm steps are covered for a while ...
    EXPECT_LT(first_keyframe, 40u);  // ... until the view has moved
}

TEST(ViewSelector, WithoutOdometryNoiseIsCoveredAndMotionIsNot) {
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.01);
    auto noisy = [&](Scan s) {
        s.odometry.reset();
        for (auto& r : s.range) r += static_cast<float>(noise(rng));
        return s;
    };
    ViewSelector v;
    const Scan a = noisy(cast(room(3.0), Pose2D{}));
    v.measure(a);
    v.accept(a);
    const ViewMeasure still = v.measure(noisy(cast(room(3.0), Pose2D{})));
    EXPECT_FALSE(still.keyframe);
    EXPECT_FALSE(still.used_odometry);
    EXPECT_LT(still.changed_fraction, 0.05);
    const ViewMeasure moved = v.measure(noisy(cast(room(3.0), Pose2D{0.4, 0.1, 0.2})));
    EXPECT_TRUE(moved.keyframe);
    EXPECT_GE(moved.changed_fraction, v.params().max_changed_fraction);
}

TEST(ViewSelector, ACorridorIsDegenerateARoomIsNot) {
    ViewSelector v;
    const ViewMeasure c = v.measure(cast(corridor(1.0, 100.0), Pose2D{}));
    const ViewMeasure r = v.measure(cast(room(3.0), Pose2D{0.3, -0.4, 0.2}));
    EXPECT_LT(c.degeneracy, 0.02);
    EXPECT_TRUE(c.corridor);
    EXPECT_GT(r.degeneracy, 0.5);
    EXPECT_FALSE(r.corridor);
}

TEST(ViewSelector, InACorridorKeyframesFollowOdometry) {
    ViewSelector::Params p;
    p.corridor_translation_m = 0.1;
    ViewSelector v(p);
    const auto world = corridor(1.0, 100.0);
    const Scan a = cast(world, Pose2D{});
    v.measure(a);
    v.accept(a);
    // 0.07 m along the corridor: under the switch's 0.1 m; 0.12 m: over it, although the
    // view change stays under max_view_change
    const ViewMeasure near = v.measure(cast(world, Pose2D{0.07, 0.0, 0.0}));
    EXPECT_TRUE(near.corridor);
    EXPECT_FALSE(near.keyframe);
    const ViewMeasure far = v.measure(cast(world, Pose2D{0.12, 0.0, 0.0}));
    EXPECT_TRUE(far.corridor);
    EXPECT_TRUE(far.keyframe);
    EXPECT_LT(far.view_change, p.max_view_change);
    // switch off: the same step is covered
    p.degeneracy_ratio = 0.0;
    ViewSelector off(p);
    off.measure(a);
    off.accept(a);
    EXPECT_FALSE(off.measure(cast(world, Pose2D{0.12, 0.0, 0.0})).keyframe);
}

TEST(ViewSelector, InACorridorWithoutOdometryKeyframesFollowTime) {
    ViewSelector v;  // corridor_interval_s = 0.2
    const auto world = corridor(1.0, 100.0);
    auto at = [&](double x, double t) {
        Scan s = cast(world, Pose2D{x, 0.0, 0.0});
        s.odometry.reset();
        s.timestamp = t;
        return s;
    };
    const Scan a = at(0.0, 10.0);
    v.measure(a);
    v.accept(a);
    EXPECT_FALSE(v.measure(at(0.05, 10.1)).keyframe);  // the walls look the same
    const ViewMeasure m = v.measure(at(0.1, 10.25));
    EXPECT_TRUE(m.corridor);
    EXPECT_TRUE(m.keyframe);
}

TEST(ViewSelector, ANewGeometryOrAnEmptyViewIsAKeyframe) {
    ViewSelector v;
    Scan a = cast(room(3.0), Pose2D{});
    a.odometry.reset();
    v.measure(a);
    v.accept(a);
    Scan b = cast(room(3.0), Pose2D{}, 181);
    b.odometry.reset();
    EXPECT_EQ(v.measure(b).changed_fraction, 1.0);
    Scan empty = test::emptyScan(361, kPi);
    EXPECT_TRUE(v.measure(empty).keyframe);
    EXPECT_EQ(v.measure(empty).degeneracy, 1.0);  // too few tangents: no verdict
}

TEST(ViewSelector, ResetForgetsTheKeyframe) {
    ViewSelector v;
    const Scan a = cast(room(3.0), Pose2D{});
    v.measure(a);
    v.accept(a);
    EXPECT_TRUE(v.hasKeyframe());
    v.reset();
    EXPECT_FALSE(v.hasKeyframe());
    EXPECT_TRUE(v.measure(a).keyframe);
}

TEST(ViewSelector, RejectsBadParams) {
    auto field = [](void (*edit)(ViewSelector::Params&)) {
        ViewSelector::Params p;
        edit(p);
        try {
            ViewSelector v(p);
        } catch (const ParameterError& e) {
            return e.field();
        }
        return std::string("<no error>");
    };
    EXPECT_EQ(field([](auto& p) { p.max_samples = 1; }), "max_samples");
    EXPECT_EQ(field([](auto& p) { p.tolerance_m = 0.0; }), "tolerance_m");
    EXPECT_EQ(field([](auto& p) { p.tolerance_deg = 90.0; }), "tolerance_deg");
    EXPECT_EQ(field([](auto& p) { p.max_view_change = std::nan(""); }), "max_view_change");
    EXPECT_EQ(field([](auto& p) { p.change_tolerance_m = -1.0; }), "change_tolerance_m");
    EXPECT_EQ(field([](auto& p) { p.change_tolerance_ratio = -0.1; }), "change_tolerance_ratio");
    EXPECT_EQ(field([](auto& p) { p.max_changed_fraction = 0.0; }), "max_changed_fraction");
    EXPECT_EQ(field([](auto& p) { p.degeneracy_ratio = 1.5; }), "degeneracy_ratio");
    EXPECT_EQ(field([](auto& p) { p.corridor_translation_m = 0.0; }), "corridor_translation_m");
    EXPECT_EQ(field([](auto& p) { p.corridor_rotation_deg = 400.0; }), "corridor_rotation_deg");
    EXPECT_EQ(field([](auto& p) { p.corridor_interval_s = -1.0; }), "corridor_interval_s");
}

TEST(KeyframeSelectorView, GuardsStillApplyAndReasonsNameTheRule) {
    ViewKeyframeSelector::Params p;
    p.max_consecutive_drops = 3;
    p.max_interval_s = 0.0;
    ViewKeyframeSelector s(p);
    const Scan a = cast(room(3.0), Pose2D{});
    std::vector<KeyframeReason> reasons;
    for (int k = 0; k < 5; ++k) reasons.push_back(s.filter(a).reason);
    const auto C = KeyframeReason::Covered;
    EXPECT_EQ(reasons, (std::vector<KeyframeReason>{KeyframeReason::First, C, C, C,
                                                    KeyframeReason::MaxDrops}));
    const auto d = s.filter(cast(room(3.0), Pose2D{1.0, 0.0, 0.0}));
    EXPECT_EQ(d.reason, KeyframeReason::ViewChange);
    EXPECT_GT(d.view_change, p.view.max_view_change);
    const auto world = corridor(1.0, 100.0);
    ViewKeyframeSelector c(p);
    c.filter(cast(world, Pose2D{}));
    const auto e = c.filter(cast(world, Pose2D{0.6, 0.0, 0.0}));  // beyond 0.5 m
    EXPECT_EQ(e.reason, KeyframeReason::Corridor);
    EXPECT_TRUE(e.corridor);
}

}  // namespace
}  // namespace kfd
