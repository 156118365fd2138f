// The odometry check (issue 22) on scans ray-cast in small hand-made rooms: odometry that
// agrees with the scans passes, frozen odometry of a moving sensor and jumps the scans do not
// show are withheld, a corridor is never mistaken for a jump.
#include "kfd/algorithms/odometry_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/algorithms/pose.h"
#include "test_scans.h"

namespace kfd {
namespace {

using test::Segment;

// A 6 x 4 m room with a 0.6 m box in it, or a 2 m wide corridor 100 m long.
std::vector<Segment> room() {
    return {{-3, -2, 3, -2},    {3, -2, 3, 2},        {3, 2, -3, 2},      {-3, 2, -3, -2},
            {1, 0.5, 1.6, 0.5}, {1.6, 0.5, 1.6, 1.1}, {1.6, 1.1, 1, 1.1}, {1, 1.1, 1, 0.5}};
}
std::vector<Segment> corridor() { return {{-50, -1, 50, -1}, {-50, 1, 50, 1}}; }

// A 361-beam, 180-degree scan from `pose` (the sensor on the robot's origin) with `odometry`.
Scan cast(const std::vector<Segment>& world, const Pose2D& pose, std::optional<Pose2D> odometry) {
    Scan s = test::castScan(world, pose);
    s.odometry = odometry;
    return s;
}

TEST(OdometryCheck, OdometryThatMovesWithTheScansIsUsedAsGiven) {
    OdometryCheck check;
    for (int k = 0; k < 20; ++k) {
        const Pose2D p{-2.0 + 0.1 * k, -0.5, 0.03 * k};
        Scan s = cast(room(), p, p);
        const auto r = check.check(s);
        EXPECT_EQ(r.verdict, OdometryVerdict::Ok) << k;
        ASSERT_TRUE(s.odometry) << k;
        EXPECT_NEAR(s.odometry->x, p.x, 1e-12);
        EXPECT_NEAR(s.odometry->phi, p.phi, 1e-12);
    }
}

TEST(OdometryCheck, ZeroOdometryOfAWalkingSensorIsWithheldOnceTheScansChanged) {
    // A laser-only log converted to a rawlog: odometry all zero while the sensor walks.
    OdometryCheck check;
    std::vector<OdometryVerdict> v;
    for (int k = 0; k < 30; ++k) {
        Scan s = cast(room(), Pose2D{-2.0 + 0.1 * k, -0.5, 0.02 * k}, Pose2D{});
        v.push_back(check.check(s).verdict);
        EXPECT_EQ(s.odometry.has_value(), v.back() == OdometryVerdict::Ok) << k;
    }
    EXPECT_EQ(v.front(), OdometryVerdict::Ok);
    const auto first_frozen = std::find(v.begin(), v.end(), OdometryVerdict::Frozen) - v.begin();
    EXPECT_GT(first_frozen, 0);
    EXPECT_LT(first_frozen, 10);  // within a metre of walking
    for (std::size_t k = static_cast<std::size_t>(first_frozen); k < v.size(); ++k)
        EXPECT_EQ(v[k], OdometryVerdict::Frozen) << k;  // until the odometry moves again
}

TEST(OdometryCheck, StillOdometryOfAStillSensorIsKept) {
    OdometryCheck check;
    for (int k = 0; k < 30; ++k) {
        Scan s = cast(room(), Pose2D{0.5, -1.0, 0.3}, Pose2D{7.0, 3.0, 1.0});
        for (std::size_t i = 0; i < s.size(); i += 7) s.range[i] += 0.01f * ((k + i) % 3);
        EXPECT_EQ(check.check(s).verdict, OdometryVerdict::Ok) << k;
    }
}

TEST(OdometryCheck, AJumpTheScansDoNotShowIsWithheldAndTakenOut) {
    // 20 steps of 5 cm set the pace; then the odometry jumps 1.5 m sideways at scan 20.
    OdometryCheck check;
    for (int k = 0; k < 26; ++k) {
        const Pose2D truth{-2.0 + 0.05 * k, -0.5, 0.0};
        Pose2D odo = truth;
        if (k >= 20) odo.y += 1.5;
        Scan s = cast(room(), truth, odo);
        const auto r = check.check(s);
        if (k == 20) {
            EXPECT_EQ(r.verdict, OdometryVerdict::Jump);
            EXPECT_GT(r.agree_still, r.agree_odometry + 0.3);
            EXPECT_FALSE(s.odometry);
            continue;
        }
        EXPECT_EQ(r.verdict, OdometryVerdict::Ok) << k;
        ASSERT_TRUE(s.odometry);
        // After the jump the odometry carries on from scan 19: 0.05 m short, not 1.5 m off.
        EXPECT_NEAR(s.odometry->y, truth.y, 1e-9) << k;
        EXPECT_NEAR(s.odometry->x, k > 20 ? truth.x - 0.05 : truth.x, 1e-9) << k;
    }
}

TEST(OdometryCheck, StepsAtTheLogsPaceAreNeverJumps) {
    // Odometry driving forward while the scans show the sensor backing up (what a point between
    // beams on a grazing wall can look like): at the log's own pace this is never a jump.
    OdometryCheck check;
    for (int k = 0; k < 30; ++k) {
        const Pose2D truth{1.0 - 0.1 * k, -0.5, 0.0};
        Scan s = cast(room(), truth, Pose2D{-truth.x, truth.y, 0.0});
        EXPECT_EQ(check.check(s).verdict, OdometryVerdict::Ok) << k;
    }
}

TEST(OdometryCheck, MovingAlongACorridorIsNoJump) {
    // Along a corridor every beam but the far ends looks the same at every step: nothing
    // contradicts the odometry, so nothing is withheld.
    OdometryCheck check;
    for (int k = 0; k < 20; ++k) {
        const Pose2D p{0.3 * k, 0.0, 0.0};
        Scan s = cast(corridor(), p, p);
        EXPECT_EQ(check.check(s).verdict, OdometryVerdict::Ok) << k;
    }
}

TEST(OdometryCheck, ScansWithoutOdometryPassUnchanged) {
    OdometryCheck check;
    Scan s = cast(room(), Pose2D{}, std::nullopt);
    EXPECT_EQ(check.check(s).verdict, OdometryVerdict::None);
    EXPECT_FALSE(s.odometry);
    EXPECT_STREQ(toString(OdometryVerdict::Frozen), "frozen");
}

TEST(OdometryCheck, BadParametersAreRejected) {
    auto bad = [](auto change) {
        OdometryCheck::Params p;
        change(p);
        EXPECT_THROW(OdometryCheck{p}, ParameterError);
    };
    bad([](auto& p) { p.frozen_changed_fraction = 0.0; });
    bad([](auto& p) { p.frozen_changed_fraction = 1.0; });
    bad([](auto& p) { p.jump_margin = std::nan(""); });
    bad([](auto& p) { p.max_samples = 2; });
    bad([](auto& p) { p.still_m = -1.0; });
    bad([](auto& p) { p.min_beams = 0; });
    bad([](auto& p) { p.jump_pace_factor = 0.5; });
}

}  // namespace
}  // namespace kfd
