// kfd/eval/trajectory.h: SE(2) helpers, TUM I/O, lookup by stamp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "kfd/eval/trajectory.h"

using kfd::Pose2D;

namespace {
void expectPose(const Pose2D& a, const Pose2D& b, double tol = 1e-9) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(kfd::wrapAngle(a.phi - b.phi), 0.0, tol);
}
std::string tempFile(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("kfd_traj_" + name)).string();
}
}  // namespace

TEST(Trajectory, ComposeByHand) {
    // Robot at (1, 2) facing +y; a step of (1, 0) forward lands at (1, 3).
    expectPose(kfd::compose({1, 2, M_PI / 2}, {1, 0, 0}), {1, 3, M_PI / 2});
    expectPose(kfd::compose({0, 0, M_PI / 2}, {0, 0, M_PI / 2}), {0, 0, M_PI});
}

TEST(Trajectory, InverseAndBetween) {
    const Pose2D a{1.5, -2.0, 0.7}, b{-0.3, 4.0, -2.9};
    expectPose(kfd::compose(a, kfd::inverse(a)), {0, 0, 0});
    expectPose(kfd::compose(a, kfd::between(a, b)), b);
    expectPose(kfd::between({0, 0, 0}, b), b);
}

TEST(Trajectory, WrapAngle) {
    EXPECT_NEAR(kfd::wrapAngle(3 * M_PI / 2), -M_PI / 2, 1e-12);
    EXPECT_NEAR(kfd::wrapAngle(-3 * M_PI / 2), M_PI / 2, 1e-12);
    EXPECT_NEAR(kfd::wrapAngle(-M_PI), M_PI, 1e-12);  // (-pi, pi]
    EXPECT_NEAR(kfd::wrapAngle(0.25), 0.25, 1e-15);
}

TEST(Trajectory, TravelIsDistanceAndWrappedTurn) {
    const auto t = kfd::travel({1, 2, 3.0}, {4, 6, -3.0});  // 3-4-5; -3 - 3 wraps to 2 pi - 6
    EXPECT_NEAR(t.metres, 5.0, 1e-12);
    EXPECT_NEAR(t.degrees, (2 * M_PI - 6.0) * 180.0 / M_PI, 1e-9);
    const auto none = kfd::travel({1, 2, 0.5}, {1, 2, 0.5});
    EXPECT_EQ(none.metres, 0.0);
    EXPECT_EQ(none.degrees, 0.0);
}

TEST(Trajectory, TumRoundTrip) {
    kfd::Trajectory t{{100.5, {1, 2, 0.3}}, {101.0, {-4, 5, -3.0}}, {101.25, {0, 0, M_PI}}};
    const auto f = tempFile("roundtrip.tum");
    kfd::writeTum(f, t);
    const auto back = kfd::readTum(f);
    ASSERT_EQ(back.size(), t.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
        EXPECT_NEAR(back[i].t, t[i].t, 1e-6);
        expectPose(back[i].pose, t[i].pose, 1e-6);
    }
    std::filesystem::remove(f);
}

TEST(Trajectory, TumLinesHoldAnyDouble) {
    // A pose of 1e250 m needs 250 digits in %f: written whole, read back exactly as printed.
    const std::string path = ::testing::TempDir() + "kfd_far.tum";
    kfd::writeTum(path, {{1.5, {1e250, -4.52e5, 0.25}}, {2.5, {-1e300, 5.411e6, -0.5}}});
    const auto back = kfd::readTum(path);
    ASSERT_EQ(back.size(), 2u);
    EXPECT_DOUBLE_EQ(back[0].pose.x, 1e250);
    EXPECT_DOUBLE_EQ(back[0].pose.y, -4.52e5);
    EXPECT_DOUBLE_EQ(back[1].pose.x, -1e300);
    EXPECT_NEAR(back[1].pose.phi, -0.5, 1e-9);
    std::remove(path.c_str());
}

TEST(Trajectory, MalformedTumNamesTheLine) {
    const auto f = tempFile("bad.tum");
    std::ofstream(f) << "# header\n1 2 3 0 0 0 0 1\n1 2 three\n";
    try {
        kfd::readTum(f);
        FAIL();
    } catch (const kfd::EvalError& e) {
        EXPECT_NE(std::string(e.what()).find(":3:"), std::string::npos) << e.what();
    }
    std::filesystem::remove(f);
    EXPECT_THROW(kfd::readTum("/nonexistent/x.tum"), kfd::EvalError);
}

TEST(Trajectory, NearestWithinTolerance) {
    kfd::Trajectory t{{1.0, {}}, {2.0, {}}, {3.0, {}}};
    EXPECT_EQ(kfd::nearest(t, 2.0004, 1e-3).value(), 1u);
    EXPECT_EQ(kfd::nearest(t, 0.9995, 1e-3).value(), 0u);
    EXPECT_EQ(kfd::nearest(t, 3.0009, 1e-3).value(), 2u);
    EXPECT_FALSE(kfd::nearest(t, 2.5, 1e-3).has_value());
    EXPECT_EQ(kfd::nearest(t, 2.4, 0.5).value(), 1u);
    EXPECT_EQ(kfd::nearest(t, 2.6, 0.5).value(), 2u);
    EXPECT_FALSE(kfd::nearest({}, 1.0, 1.0).has_value());
}
