// kfd::ros2::typeHash: ROS 2's type hashes (REP 2011) computed from the types' descriptions.
// The expected values are the ones rosidl generates for Humble/Jazzy's message packages.
#include "kfd/ros2/type_hash.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace {

using kfd::ros2::ddsTypeName;
using kfd::ros2::typeHash;

TEST(TypeHash, MatchesRosidlForTimeHeaderAndLaserScan) {
    EXPECT_EQ(typeHash("builtin_interfaces/msg/Time"),
              "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197");
    EXPECT_EQ(typeHash("std_msgs/msg/Header"),
              "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01");
    EXPECT_EQ(typeHash("sensor_msgs/msg/LaserScan"),
              "RIHS01_64c191398013af96509d518dac71d5164f9382553fce5c1f8cca5be7924bd828");
}

TEST(TypeHash, EveryTypeTheNodeSpeaksHasOne) {
    for (const char* t : {"nav_msgs/msg/Odometry", "tf2_msgs/msg/TFMessage",
                          "diagnostic_msgs/msg/DiagnosticArray"}) {
        const std::string h = typeHash(t);
        EXPECT_EQ(h.size(), 7u + 64u) << t;
        EXPECT_EQ(h.rfind("RIHS01_", 0), 0u) << t;
    }
    EXPECT_NE(typeHash("nav_msgs/msg/Odometry"), typeHash("tf2_msgs/msg/TFMessage"));
}

TEST(TypeHash, ReferencedTypesAreListedOnceSortedByName) {
    const std::string j = kfd::ros2::typeDescriptionJson("sensor_msgs/msg/LaserScan");
    const auto time = j.find("\"type_name\": \"builtin_interfaces/msg/Time\"");
    const auto header = j.find("\"type_name\": \"std_msgs/msg/Header\"");
    ASSERT_NE(time, std::string::npos);
    ASSERT_NE(header, std::string::npos);
    EXPECT_LT(time, header);
    EXPECT_EQ(j.find("\"type_name\": \"std_msgs/msg/Header\"", header + 1), std::string::npos);
}

TEST(TypeHash, UnknownTypeIsRefused) {
    EXPECT_THROW(typeHash("sensor_msgs/msg/Image"), std::invalid_argument);
}

TEST(DdsTypeName, FollowsRmwNaming) {
    EXPECT_EQ(ddsTypeName("sensor_msgs/msg/LaserScan"), "sensor_msgs::msg::dds_::LaserScan_");
    EXPECT_THROW(ddsTypeName("LaserScan"), std::invalid_argument);
}

}  // namespace
