// kfd::ros2::parseRos2Args: the ROS 2 node's settings from ROS 2's command-line form.
#include "kfd/ros2/node_params.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "kfd/mrpt/config.h"

namespace {

using kfd::ros2::parseRos2Args;
using kfd::ros2::Ros2Config;

kfd::ros2::Ros2Args parse(std::vector<const char*> args) {
    args.insert(args.begin(), "kfd_ros2");
    return parseRos2Args(static_cast<int>(args.size()), args.data());
}

TEST(Ros2Args, DefaultsAreTheRos1NodesAndTheEnvironmentsDomain) {
    setenv("ROS_DOMAIN_ID", "7", 1);
    setenv("ROS_LOCALHOST_ONLY", "1", 1);
    const Ros2Config c = parse({}).config;
    unsetenv("ROS_DOMAIN_ID");
    unsetenv("ROS_LOCALHOST_ONLY");
    EXPECT_EQ(c.odometry, Ros2Config::Odometry::Tf);
    EXPECT_EQ(c.odom_frame, "odom");
    EXPECT_EQ(c.domain_id, 7);
    EXPECT_TRUE(c.localhost_only);
    EXPECT_EQ(c.scan_reliability, kfd::ros2::Reliability::BestEffort);
    EXPECT_EQ(c.ddsTopic("scan"), "rt/scan");
}

TEST(Ros2Args, ParametersRemapsAndNamespace) {
    const Ros2Config c =
        parse({"--ros-args", "-p", "odom:=topic", "-p", "domain_id:=42", "-p", "scan_qos:=reliable",
               "-r", "scan:=/front/scan", "-r", "__ns:=/robot1"})
            .config;
    EXPECT_EQ(c.odometry, Ros2Config::Odometry::Topic);
    EXPECT_EQ(c.domain_id, 42);
    EXPECT_EQ(c.scan_reliability, kfd::ros2::Reliability::Reliable);
    EXPECT_EQ(c.ddsTopic("scan"), "rt/front/scan");
    EXPECT_EQ(c.ddsTopic("scan_filtered"), "rt/robot1/scan_filtered");
    EXPECT_EQ(c.ddsTopic("/tf"), "rt/tf");
}

TEST(Ros2Args, KfdKeysAsStageDotKey) {
    const Ros2Config c = parse({"--ros-args", "-p", "distance.max_range:=12.5"}).config;
    const Ros2Config d = parse({}).config;
    EXPECT_NE(kfd::toIni(c.pipeline), kfd::toIni(d.pipeline));
}

TEST(Ros2Args, ParamsFileIsReadLikeRos2s) {
    const auto path = std::filesystem::temp_directory_path() / "kfd_ros2_params.yaml";
    std::ofstream(path) << "/**:\n  ros__parameters:\n    odom: none\n    distance:\n"
                           "      max_range: 12.5\n";
    const Ros2Config c = parse({"--ros-args", "--params-file", path.c_str()}).config;
    EXPECT_EQ(c.odometry, Ros2Config::Odometry::None);
    EXPECT_EQ(kfd::toIni(c.pipeline),
              kfd::toIni(parse({"--ros-args", "-p", "distance.max_range:=12.5", "-p", "odom:=none"})
                             .config.pipeline));
}

TEST(Ros2Args, BadValuesNameTheParameter) {
    const std::vector<std::vector<const char*>> bad = {
        {"--ros-args", "-p", "odom:=wheel"},
        {"--ros-args", "-p", "domain_id:=999"},
        {"--ros-args", "-p", "tf_wait:=abc"},
        {"--ros-args", "-p", "queue_size:=0"},
        {"--ros-args", "-p", "scan_qos:=fast"},
        {"--ros-args", "-p", "distance.no_such_key:=1"},
        {"--ros-args", "-p", "no_such_stage.x:=1"},
        {"--ros-args", "-p", "odom"},
        {"--ros-args", "-p"},
        {"--ros-args", "--params-file", "/nonexistent/kfd.yaml"},
        {"--unknown"},
    };
    for (const auto& args : bad) {
        std::string joined;
        for (const char* a : args) joined += std::string(a) + " ";
        EXPECT_THROW(parse(args), kfd::ConfigError) << joined;
    }
}

TEST(Ros2Args, HelpNeedsNoConfiguration) { EXPECT_TRUE(parse({"--help"}).help); }

}  // namespace
