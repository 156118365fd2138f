// kfd::live::OdometryBuffer: the pose at a scan's stamp from an odometry topic, by the bag
// source's rule, in bounded memory.
#include "kfd/live/odometry_buffer.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using kfd::Pose2D;
using kfd::live::OdometryBuffer;

TEST(OdometryBuffer, InterpolatesBetweenTheSamplesAroundTheStamp) {
    OdometryBuffer b;
    b.add(1.0, Pose2D{0.0, 0.0, 3.0});
    b.add(2.0, Pose2D{1.0, 2.0, -3.0});  // yaw crosses +-pi: the short way
    const auto p = b.at(1.5);
    ASSERT_TRUE(p);
    EXPECT_DOUBLE_EQ(p->x, 0.5);
    EXPECT_DOUBLE_EQ(p->y, 1.0);
    EXPECT_NEAR(std::fabs(p->phi), M_PI, 1e-9);
    EXPECT_DOUBLE_EQ(b.at(2.0)->x, 1.0);
}

TEST(OdometryBuffer, HoldsTheNearestSampleForOneSecondThenUnknown) {
    OdometryBuffer b;
    b.add(10.0, Pose2D{1.0, 0.0, 0.0});
    b.add(11.0, Pose2D{2.0, 0.0, 0.0});
    EXPECT_DOUBLE_EQ(b.at(11.9)->x, 2.0);  // odometry late: the newest sample
    EXPECT_FALSE(b.at(12.1));              // too late: unknown (counted odom_missing)
    EXPECT_DOUBLE_EQ(b.at(9.5)->x, 1.0);
    EXPECT_FALSE(b.at(8.9));
}

TEST(OdometryBuffer, KeepsAtMostItsCapacity) {
    OdometryBuffer b(OdometryBuffer::Params{8, 1.0});
    for (int i = 0; i < 100; ++i) b.add(i, Pose2D{double(i), 0.0, 0.0});
    EXPECT_EQ(b.size(), 8u);
    EXPECT_FALSE(b.at(50.0));  // forgotten
    EXPECT_DOUBLE_EQ(b.at(95.5)->x, 95.5);
}

TEST(OdometryBuffer, IgnoresNonFiniteAndOlderSamples) {
    OdometryBuffer b;
    b.add(1.0, Pose2D{1.0, 0.0, 0.0});
    b.add(2.0, Pose2D{NAN, 0.0, 0.0});
    b.add(0.5, Pose2D{5.0, 0.0, 0.0});
    EXPECT_EQ(b.size(), 1u);
    EXPECT_DOUBLE_EQ(b.newest(), 1.0);
}

}  // namespace
