// kfd::ros2::Ros2Node without DDS: CDR bytes in, CDR bytes out, a hand-set clock. Its decisions
// are the live front end's (kfd::live::LiveFilter) on the same messages; a scan waits for the
// odometry after its stamp, never longer than tf_wait; bad bytes are counted, never fatal.
#include "kfd/ros2/ros2_node.h"

#include <gtest/gtest.h>

#include <cmath>

#include "kfd/io/ros2_message.h"
#include "kfd/mrpt/config.h"
#include "ros1/laser_scans.h"

namespace {

using kfd::ros2::Bytes;
using kfd::ros2::Ros2Config;
using kfd::ros2::Ros2Node;
using kfd::ros2::Ros2Outputs;
using kfd::test::roomScan;

struct Harness {
    double clock = 0.0;
    std::vector<sensor_msgs::LaserScan> out;
    std::vector<std::string> logs;
    Bytes last_diag;
    std::unique_ptr<Ros2Node> node;

    explicit Harness(Ros2Config c) {
        Ros2Outputs o;
        o.scan_filtered = [this](const Bytes& b) {
            sensor_msgs::LaserScan m;
            kfd::decodeRos2(b.data(), b.size(), m);
            out.push_back(m);
        };
        o.diagnostics = [this](const Bytes& b) { last_diag = b; };
        o.log = [this](const std::string& s) { logs.push_back(s); };
        node = std::make_unique<Ros2Node>(c, o, [this] { return clock; });
    }
    void scan(const sensor_msgs::LaserScan& m) {
        const Bytes b = kfd::encodeRos2(m);
        node->onScan(b.data(), b.size());
    }
    void odom(double stamp, double x) {
        nav_msgs::Odometry o;
        o.header.stamp.fromSec(stamp);
        o.header.frame_id = "odom";
        o.child_frame_id = "base_link";
        o.pose.pose.position.x = x;
        o.pose.pose.orientation.w = 1.0;
        const Bytes b = kfd::encodeRos2(o);
        node->onOdometry(b.data(), b.size());
    }
    std::map<std::string, std::string> diagnostics() {
        node->publishDiagnostics(1.0);
        diagnostic_msgs::DiagnosticArray a;
        kfd::decodeRos2(last_diag.data(), last_diag.size(), a);
        std::map<std::string, std::string> kv;
        for (const auto& v : a.status.at(0).values) kv[v.key] = v.value;
        kv["level"] = std::to_string(a.status.at(0).level);
        return kv;
    }
};

Ros2Config config(Ros2Config::Odometry odom) {
    Ros2Config c;
    c.pipeline = kfd::kfdDefaults();
    c.odometry = odom;
    return c;
}

TEST(Ros2Node, DecidesAsTheLiveFrontEndOnTheSameScans) {
    Harness h(config(Ros2Config::Odometry::None));
    kfd::live::LiveFilter ref(kfd::live::LiveFilter::Params{kfd::kfdDefaults()});
    std::vector<sensor_msgs::LaserScan> expected;
    for (int i = 0; i < 40; ++i) {
        auto m = roomScan(100.0 + 0.1 * i, "laser", 181, 0.02 * i);
        h.scan(m);
        const auto r = ref.process(m, 100.0 + 0.1 * i, std::nullopt, false);
        for (sensor_msgs::LaserScan::Ptr d; ref.takeReady(d);) expected.push_back(*d);
        if (r.publish) expected.push_back(m);
    }
    h.node->finish();
    ref.finish();
    for (sensor_msgs::LaserScan::Ptr d; ref.takeReady(d);) expected.push_back(*d);
    ASSERT_EQ(h.out.size(), expected.size());
    ASSERT_GT(expected.size(), 0u);
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(h.out[i].header.stamp, expected[i].header.stamp);
        EXPECT_EQ(h.out[i].ranges.size(), expected[i].ranges.size());
    }
    EXPECT_EQ(h.node->counters().scans_in, 40u);
}

TEST(Ros2Node, AScanWaitsForTheOdometryAfterItsStamp) {
    Harness h(config(Ros2Config::Odometry::Topic));
    h.odom(99.95, 0.0);
    h.scan(roomScan(100.0));
    EXPECT_EQ(h.node->waiting(), 1u);  // the sample after 100.0 has not come
    EXPECT_TRUE(h.out.empty());
    h.odom(100.05, 0.01);
    EXPECT_EQ(h.node->waiting(), 0u);
    EXPECT_EQ(h.out.size(), 1u);  // the first scan is a keyframe
    EXPECT_EQ(h.node->counters().odom_missing, 0u);
}

TEST(Ros2Node, MissingOdometryCostsOneWaitThenLaserOnlyUntilItComesBack) {
    Ros2Config c = config(Ros2Config::Odometry::Topic);
    c.tf_wait = 0.5;
    Harness h(c);
    h.scan(roomScan(100.0));
    h.clock = 0.4;
    h.node->tick();
    EXPECT_EQ(h.node->waiting(), 1u);
    h.clock = 0.6;
    h.node->tick();
    EXPECT_EQ(h.node->waiting(), 0u);
    EXPECT_EQ(h.node->ownCounters().odom_timeouts, 1u);
    EXPECT_EQ(h.logs.size(), 1u);
    h.scan(roomScan(100.1));  // odometry is down: no wait
    EXPECT_EQ(h.node->waiting(), 0u);
    EXPECT_EQ(h.node->counters().odom_missing, 2u);
    h.odom(100.15, 0.0);  // back: the next scan waits for its sample again
    h.scan(roomScan(100.2));
    EXPECT_EQ(h.node->waiting(), 1u);
}

TEST(Ros2Node, AFullQueueFiltersTheOldestScanWithoutLosingIt) {
    Ros2Config c = config(Ros2Config::Odometry::Topic);
    c.queue_size = 3;
    Harness h(c);
    h.odom(99.0, 0.0);
    for (int i = 0; i < 6; ++i) h.scan(roomScan(100.0 + 0.1 * i));
    EXPECT_EQ(h.node->waiting(), 3u);
    EXPECT_EQ(h.node->ownCounters().queue_full, 3u);
    h.node->finish();
    EXPECT_EQ(h.node->waiting(), 0u);
    EXPECT_EQ(h.node->counters().scans_in, 6u);
}

TEST(Ros2Node, BadBytesOnEveryInputAreCountedAndTheNodeGoesOn) {
    Harness h(config(Ros2Config::Odometry::Tf));
    const std::vector<std::uint8_t> junk = {0, 1, 0, 0, 0xff, 0xff, 0xff, 0x7f, 1, 2};
    h.node->onScan(junk.data(), junk.size());
    h.node->onOdometry(junk.data(), junk.size());
    h.node->onTf(junk.data(), junk.size(), false);
    h.node->onTf(junk.data(), junk.size(), true);
    h.node->onScan(nullptr, 0);
    EXPECT_EQ(h.node->ownCounters().bad_messages, 5u);
    EXPECT_EQ(h.logs.size(), 1u);  // the first one only
    auto d = h.diagnostics();
    EXPECT_EQ(d["bad_messages"], "5");
    EXPECT_EQ(d["level"], "1");                // WARN: bad messages since the last report
    EXPECT_EQ(h.diagnostics()["level"], "0");  // none since
}

TEST(Ros2Node, TheLaserMountComesFromTfStaticAsOfflineAndOdometryFromTf) {
    Harness h(config(Ros2Config::Odometry::Tf));
    tf2_msgs::TFMessage st, tf;
    geometry_msgs::TransformStamped t;
    t.header.frame_id = "base_link";
    t.child_frame_id = "laser";
    t.transform.translation.x = 0.2;
    t.transform.rotation.w = 1.0;
    st.transforms.push_back(t);
    const Bytes sb = kfd::encodeRos2(st);
    h.node->onTf(sb.data(), sb.size(), true);
    h.scan(roomScan(100.0));
    EXPECT_EQ(h.node->waiting(), 1u);
    t.header.frame_id = "/odom";  // a leading '/' is the same frame
    t.child_frame_id = "base_link";
    t.header.stamp.fromSec(100.01);
    tf.transforms.push_back(t);
    const Bytes tb = kfd::encodeRos2(tf);
    h.node->onTf(tb.data(), tb.size(), false);
    EXPECT_EQ(h.node->waiting(), 0u);
    EXPECT_EQ(h.node->counters().odom_missing, 0u);
}

}  // namespace

namespace {

TEST(Ros2Node, WithTheTrackStageEveryScanGetsATrackedPose) {
    const Ros2Config c = config(Ros2Config::Odometry::None);  // kfd's defaults list `track`
    ASSERT_TRUE(c.pipeline.lists("track"));
    std::vector<nav_msgs::Odometry> poses;
    Ros2Outputs o;
    o.track = [&](const Bytes& b) {
        nav_msgs::Odometry m;
        kfd::decodeRos2(b.data(), b.size(), m);
        poses.push_back(m);
    };
    Ros2Node node(c, o, [] { return 0.0; });
    for (int i = 0; i < 10; ++i) {
        const Bytes b = kfd::encodeRos2(roomScan(100.0 + 0.1 * i, "laser", 181, 0.02 * i));
        node.onScan(b.data(), b.size());
    }
    ASSERT_EQ(poses.size(), 10u);
    EXPECT_EQ(poses.back().header.frame_id, "odom");
    EXPECT_EQ(poses.back().child_frame_id, "base_link");
    // The robot moved 0.18 m along +x over the ten scans (laser only: the tracker found it).
    EXPECT_NEAR(poses.back().pose.pose.position.x - poses.front().pose.pose.position.x, 0.18, 0.05);
}

}  // namespace
