// kfd::ros1::nodeConfig: the node's private parameters, kfd's keys validated as kfd-filter
// validates a -c file; anything unknown, bad or of the wrong type names its key.
#include "kfd/ros1/node_config.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "kfd/mrpt/config.h"

namespace {

using kfd::ros1::NodeConfig;
using kfd::ros1::nodeConfig;
using Params = std::map<std::string, XmlRpc::XmlRpcValue>;

// The key a ConfigError names, or "" when nodeConfig accepts `p`.
std::string refusedKey(const Params& p) {
    try {
        nodeConfig(p);
    } catch (const kfd::ConfigError& e) {
        return e.key();
    }
    return "";
}

TEST(NodeConfig, NoParametersGiveKfdDefaults) {
    const NodeConfig c = nodeConfig({});
    EXPECT_EQ(kfd::toIni(c.pipeline), kfd::toIni(kfd::kfdDefaults()));
    EXPECT_EQ(c.odometry, NodeConfig::Odometry::Tf);
    EXPECT_EQ(c.odom_frame, "odom");
    EXPECT_EQ(c.base_frame, "base_link");
    EXPECT_DOUBLE_EQ(c.tf_wait, 1.0);
    EXPECT_EQ(c.removed, kfd::RemovedMark::NaN);
}

TEST(NodeConfig, KeyParametersOverrideTheConfigFile) {
    const std::string path = ::testing::TempDir() + "node_config_test.ini";
    std::ofstream(path) << "[KFD]\nwindow = 2\nbins = 30\n";
    Params p;
    p["config"] = path;
    p["window"] = 3;          // an int
    p["p_pair"] = 0.9;        // a double
    p["selector"] = "paper";  // a string
    const NodeConfig c = nodeConfig(p);
    const std::string ini = kfd::toIni(c.pipeline);
    EXPECT_NE(ini.find("window = 3"), std::string::npos) << ini;
    EXPECT_NE(ini.find("bins = 30"), std::string::npos) << ini;
    EXPECT_NE(ini.find("p_pair = 0.9"), std::string::npos) << ini;
    // selector = paper: the paper's keyframe stage where the default's view_keyframe was.
    EXPECT_NE(ini.find("pipeline = odometry_check, distance, track, keyframe, evidence_denoise"),
              std::string::npos)
        << ini;
    std::remove(path.c_str());
}

TEST(NodeConfig, PipelineListIsTheStageList) {
    Params p;
    XmlRpc::XmlRpcValue list;
    list[0] = "distance";
    list[1] = "keyframe";
    p["pipeline"] = list;
    const std::string ini = kfd::toIni(nodeConfig(p).pipeline);
    EXPECT_NE(ini.find("pipeline = distance, keyframe"), std::string::npos) << ini;
}

TEST(NodeConfig, UnknownKeyIsRefusedByName) {
    Params p;
    p["windw"] = 3;
    EXPECT_EQ(refusedKey(p), "windw");
}

TEST(NodeConfig, BadValueIsRefusedByName) {
    Params p;
    p["window"] = -1;
    EXPECT_EQ(refusedKey(p), "window");
    Params q;
    q["p_pair"] = "lots";
    EXPECT_EQ(refusedKey(q), "p_pair");
}

TEST(NodeConfig, WrongTypeIsRefusedByName) {
    Params p;
    XmlRpc::XmlRpcValue map;
    map["a"] = 1;
    p["window"] = map;
    EXPECT_EQ(refusedKey(p), "window");
    Params q;
    q["tf_wait"] = "soon";
    EXPECT_EQ(refusedKey(q), "tf_wait");
    Params r;
    r["odom_frame"] = 3;
    EXPECT_EQ(refusedKey(r), "odom_frame");
    Params s;
    s["config"] = 1.5;
    EXPECT_EQ(refusedKey(s), "config");
}

TEST(NodeConfig, NodeParametersAreChecked) {
    Params p;
    p["odom"] = "gps";
    EXPECT_EQ(refusedKey(p), "odom");
    Params q;
    q["removed_as"] = "zero";
    EXPECT_EQ(refusedKey(q), "removed_as");
    Params r;
    r["tf_wait"] = -0.1;
    EXPECT_EQ(refusedKey(r), "tf_wait");
    Params s;
    s["queue_size"] = 0;
    EXPECT_EQ(refusedKey(s), "queue_size");
    for (const int n : {0, 100001}) {
        Params m;
        m["max_sensors"] = n;
        EXPECT_EQ(refusedKey(m), "max_sensors");
    }
    Params ok;
    ok["max_sensors"] = 4;
    EXPECT_EQ(nodeConfig(ok).max_sensors, 4);
    ok.erase("max_sensors");
    ok["odom"] = "topic";
    ok["removed_as"] = "inf";
    ok["tf_wait"] = 0;  // an int is a number of seconds too
    const NodeConfig c = nodeConfig(ok);
    EXPECT_EQ(c.odometry, NodeConfig::Odometry::Topic);
    EXPECT_EQ(c.removed, kfd::RemovedMark::PlusInf);
    EXPECT_DOUBLE_EQ(c.tf_wait, 0.0);
}

// Issue 38: a frame id tf2 refuses in every lookup is refused at start, not warned per scan.
TEST(NodeConfig, FrameIdsTf2WouldRefuseAreRefusedAtStart) {
    for (const char* key : {"base_frame", "odom_frame"}) {
        for (const char* bad : {"/base_link", "", "base link", "//odom"}) {
            Params p;
            p[key] = bad;
            std::string message;
            try {
                nodeConfig(p);
            } catch (const kfd::ConfigError& e) {
                EXPECT_EQ(e.key(), key) << bad;
                message = e.what();
            }
            EXPECT_FALSE(message.empty()) << key << " = '" << bad << "' accepted";
            if (bad[0] == '/') {
                EXPECT_NE(message.find("do not start with '/'"), std::string::npos) << message;
            }
        }
    }
    Params ok;
    ok["base_frame"] = "robot1/base_link";  // a tf prefix inside is fine
    EXPECT_EQ(nodeConfig(ok).base_frame, "robot1/base_link");
}

TEST(NodeConfig, BadConfigFileIsRefused) {
    Params p;
    p["config"] = std::string("/nonexistent/kfd.ini");
    EXPECT_THROW(nodeConfig(p), kfd::ConfigError);
}

}  // namespace
