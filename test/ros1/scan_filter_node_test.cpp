// kfd::ros1::ScanFilterNode driven directly (onScan/onOdometry with hand-made messages) on a
// ROS master of its own: a roscore on a free loopback port, started and killed by the fixture.
#include "kfd/ros1/scan_filter_node.h"

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "kfd/mrpt/config.h"
#include "ros1/laser_scans.h"

namespace {

using kfd::ros1::ScanFilterNode;
using kfd::test::roomScan;

int freePort() {
    const int s = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    bind(s, reinterpret_cast<sockaddr*>(&a), sizeof(a));
    socklen_t n = sizeof(a);
    getsockname(s, reinterpret_cast<sockaddr*>(&a), &n);
    close(s);
    return ntohs(a.sin_port);
}

class ScanFilterNodeTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        home_ = ::testing::TempDir() + "kfd_ros_home_" + std::to_string(getpid());
        const std::string& home = home_;
        const std::string uri = "http://127.0.0.1:" + std::to_string(port_ = freePort());
        setenv("ROS_MASTER_URI", uri.c_str(), 1);
        setenv("ROS_IP", "127.0.0.1", 1);
        setenv("ROS_HOME", home.c_str(), 1);
        setenv("ROS_LOG_DIR", (home + "/log").c_str(), 1);
        core_ = fork();
        if (core_ == 0) {
            setpgid(0, 0);
            prctl(PR_SET_PDEATHSIG, SIGINT);  // a test killed by its timeout takes roscore along
            const std::string port = std::to_string(port_);
            freopen("/dev/null", "w", stdout);
            freopen("/dev/null", "w", stderr);
            execlp("roscore", "roscore", "-p", port.c_str(), static_cast<char*>(nullptr));
            _exit(127);
        }
        setpgid(core_, core_);
        int argc = 0;
        ros::init(argc, nullptr, "scan_filter_node_test", ros::init_options::NoSigintHandler);
        for (int i = 0; i < 300 && !ros::master::check(); ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        ASSERT_TRUE(ros::master::check()) << "no roscore on " << uri;
        ros::start();
    }
    static void TearDownTestSuite() {
        ros::shutdown();
        if (core_ > 0) {
            kill(-core_, SIGINT);
            for (int i = 0; i < 100 && waitpid(core_, nullptr, WNOHANG) == 0; ++i)
                std::this_thread::sleep_for(std::chrono::milliseconds(100));
            kill(-core_, SIGKILL);
            waitpid(core_, nullptr, 0);
        }
        std::error_code ignored;  // roscore's logs: nothing of them is wanted after the tests
        std::filesystem::remove_all(home_, ignored);
    }
    // A node whose private namespace is /NAME, its parameters set first.
    static std::unique_ptr<ScanFilterNode> node(const std::string& name,
                                                const std::map<std::string, std::string>& p = {}) {
        for (const auto& [k, v] : p) ros::param::set("/" + name + "/" + k, v);
        return std::make_unique<ScanFilterNode>(ros::NodeHandle("/" + name + "_ns"),
                                                ros::NodeHandle("/" + name));
    }
    static std::string refusedKey(const std::string& name) {
        try {
            node(name);
        } catch (const kfd::ConfigError& e) {
            return e.key();
        }
        return "";
    }
    static sensor_msgs::LaserScan::ConstPtr scanAt(double t) {
        return boost::make_shared<sensor_msgs::LaserScan>(roomScan(t));
    }
    // Waits (at most 5 s) until `sub` is connected to a publisher.
    static void waitForPublisher(const ros::Subscriber& sub) {
        for (int i = 0; i < 100 && sub.getNumPublishers() == 0; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    // Spins the callbacks until done() or `tries` times 20 ms.
    template <class Done>
    static void spinUntil(Done&& done, int tries) {
        for (int i = 0; i < tries && !done(); ++i) {
            ros::spinOnce();
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
    }
    static inline std::string home_;
    static inline pid_t core_ = -1;
    static inline int port_ = 0;
};

TEST_F(ScanFilterNodeTest, RefusesAnUnknownPrivateParameterNamingIt) {
    ros::param::set("/bad1/windw", 3);
    EXPECT_EQ(refusedKey("bad1"), "windw");
    ros::param::set("/bad2/window", "three");
    EXPECT_EQ(refusedKey("bad2"), "window");
    XmlRpc::XmlRpcValue map;
    map["x"] = 1;
    ros::param::set("/bad3/bins", map);  // a map where a number goes
    EXPECT_EQ(refusedKey("bad3"), "bins");
    ros::param::set("/bad4/odom", true);  // the wrong type for a node parameter
    EXPECT_EQ(refusedKey("bad4"), "odom");
}

TEST_F(ScanFilterNodeTest, ReadsItsPrivateParameters) {
    ros::param::set("/good/view_keyframe/max_view_change", 0.5);  // a stage's own: ~stage/key
    ros::param::set("/good/max_range", 30);  // a flat key of before: read, with a note
    ros::param::set("/good/odom", std::string("topic"));
    ros::param::set("/good/removed_as", std::string("inf"));
    const auto n = node("good");
    EXPECT_EQ(n->config().odometry, kfd::ros1::NodeConfig::Odometry::Topic);
    EXPECT_EQ(n->config().removed, kfd::RemovedMark::PlusInf);
    const std::string ini = kfd::toIni(n->config().pipeline);
    EXPECT_NE(ini.find("[KFD.view_keyframe]\n"), std::string::npos) << ini;
    EXPECT_NE(ini.find("max_view_change = 0.5\n"), std::string::npos) << ini;
    EXPECT_NE(ini.find("max_range = 30\n"), std::string::npos) << ini;
    ASSERT_EQ(n->config().notes.size(), 1u);
    EXPECT_NE(n->config().notes[0].find("~distance/{max_range}"), std::string::npos)
        << n->config().notes[0];
    ros::param::set("/other/keyframe/window", 3);  // a stage the pipeline does not list
    EXPECT_EQ(refusedKey("other"), "keyframe");
}

TEST_F(ScanFilterNodeTest, MissingTfFallsBackToLaserOnlyForThatScan) {
    ros::param::set("/tfnode/tf_wait", 0.01);
    auto n = node("tfnode");
    n->onScan(scanAt(100.0));  // no odom -> base_link at all: a bounded wait, then laser only
    EXPECT_EQ(n->counters().scans_in, 1u);
    EXPECT_EQ(n->counters().odom_missing, 1u);
    EXPECT_EQ(n->counters().scans_kept, 1u);
    geometry_msgs::TransformStamped t;
    t.header.frame_id = "odom";
    t.child_frame_id = "base_link";
    t.transform.rotation.w = 1.0;
    for (double s : {100.0, 100.2}) {
        t.header.stamp.fromSec(s);
        t.transform.translation.x = s - 100.0;
        n->tfBuffer().setTransform(t, "test");
    }
    n->onScan(scanAt(100.1));  // between two transforms: found
    EXPECT_EQ(n->counters().odom_missing, 1u);
    n->onScan(scanAt(105.0));  // /tf stopped long ago: missing again
    EXPECT_EQ(n->counters().odom_missing, 2u);
}

// Issue 38: a stamp near the end of ROS 1's 32-bit time aborted the node ("Time is out of
// dual 32-bit range", with the default odom: tf), and a jump of more than 2^31 s did in every
// odometry mode. Now such a scan is dropped and counted, and the node goes on.
TEST_F(ScanFilterNodeTest, AStampAtTheEndOfRosTimeOrAHugeJumpNeverKillsTheNode) {
    for (const std::string odom : {"tf", "none"}) {
        const std::string name = "stampnode_" + odom;
        ros::param::set("/" + name + "/odom", odom);
        ros::param::set("/" + name + "/tf_wait", 0.01);
        auto n = node(name);
        EXPECT_NO_THROW(n->onScan(scanAt(4294967000.0)));  // 295 s before the end
        EXPECT_EQ(n->counters().stamps_unusable, 1u) << odom;
        EXPECT_EQ(n->counters().scans_in, 1u) << odom;
        EXPECT_EQ(n->counters().scans_kept, 0u) << odom;
        EXPECT_NO_THROW(n->onScan(scanAt(1.0)));
        EXPECT_NO_THROW(n->onScan(scanAt(3.0e9)));  // a jump of more than 2^31 s
        EXPECT_NO_THROW(n->onScan(scanAt(2.0)));    // and back
        EXPECT_EQ(n->counters().scans_in, 4u) << odom;
        EXPECT_EQ(n->counters().stamps_unusable, 1u) << odom;
        EXPECT_EQ(n->counters().callback_errors, 0u) << odom;
        EXPECT_GE(n->counters().scans_kept, 1u) << odom;
        // The counters reach /diagnostics and ~stats.
        bool listed = false;
        for (const auto& kv : n->stats().values) listed = listed || kv.key == "stamps_unusable";
        EXPECT_TRUE(listed);
    }
}

// Issue 38: scans lost in the queue or before the node (a gap in header.seq), scans of unusable
// geometry and scans without the odometry the node was told to use are counted and raise the
// diagnostics to WARN, naming what happened; a healthy stream stays OK.
TEST_F(ScanFilterNodeTest, LostScansAndMissingOdometryRaiseTheDiagnostics) {
    ros::param::set("/healthy/odom", std::string("none"));
    auto ok = node("healthy");
    for (std::uint32_t seq : {7u, 8u, 9u}) {
        auto m = boost::make_shared<sensor_msgs::LaserScan>(roomScan(10.0 + 0.1 * seq));
        m->header.seq = seq;
        ok->onScan(m);
    }
    EXPECT_EQ(ok->counters().scans_missing, 0u);
    EXPECT_EQ(ok->stats().level, diagnostic_msgs::DiagnosticStatus::OK) << ok->stats().message;

    ros::param::set("/lossy/odom", std::string("none"));
    auto n = node("lossy");
    for (std::uint32_t seq : {1u, 2u, 5u, 6u, 20000u}) {  // 2 missing; 20000: a restart
        auto m = boost::make_shared<sensor_msgs::LaserScan>(roomScan(10.0 + 0.1 * seq));
        m->header.seq = seq;
        n->onScan(m);
    }
    EXPECT_EQ(n->counters().scans_missing, 2u);
    auto bad = boost::make_shared<sensor_msgs::LaserScan>(roomScan(3000.0));
    bad->angle_increment = 0.0f;  // unusable geometry
    n->onScan(bad);
    EXPECT_EQ(n->counters().scans_skipped, 1u);
    const auto s = n->stats();
    EXPECT_EQ(s.level, diagnostic_msgs::DiagnosticStatus::WARN);
    EXPECT_NE(s.message.find("2 scans missing"), std::string::npos) << s.message;
    EXPECT_NE(s.message.find("1 scans of unusable geometry"), std::string::npos) << s.message;

    ros::param::set("/noodom/tf_wait", 0.01);  // odom: tf (the default), no transform ever
    auto t = node("noodom");
    t->onScan(scanAt(50.0));
    EXPECT_EQ(t->stats().level, diagnostic_msgs::DiagnosticStatus::WARN);
    EXPECT_NE(t->stats().message.find("without odometry"), std::string::npos);
}

// The node waits in ROS time after the scan's stamp (here the wall clock: no use_sim_time).
double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

geometry_msgs::TransformStamped odomAt(double t) {
    geometry_msgs::TransformStamped m;
    m.header.frame_id = "odom";
    m.child_frame_id = "base_link";
    m.transform.rotation.w = 1.0;
    m.header.stamp.fromSec(t);
    return m;
}

TEST_F(ScanFilterNodeTest, TheWaitForTfCountsInTheLatencyButNotInTheWork) {
    ros::param::set("/waitnode/tf_wait", 0.2);
    auto n = node("waitnode");
    n->onScan(scanAt(ros::Time::now().toSec()));  // /tf never comes: waits ~tf_wait
    std::map<std::string, double> kv;
    for (const auto& v : n->stats().values) kv[v.key] = std::stod(v.value);
    EXPECT_GE(kv["latency_max_us"], 150000.0);
    EXPECT_LT(kv["work_max_us"], kv["latency_max_us"] - 100000.0);
    EXPECT_GT(kv["work_max_us"], 0.0);
    EXPECT_EQ(n->counters().odom_missing, 1u);
}

TEST_F(ScanFilterNodeTest, WhileTfIsDownScansDoNotWaitUntilANewerTransformComes) {
    ros::param::set("/downnode/tf_wait", 0.5);
    auto n = node("downnode");
    const double t0 = ros::Time::now().toSec();
    auto start = std::chrono::steady_clock::now();
    n->onScan(scanAt(t0));  // the first wait runs out: /tf is down
    EXPECT_GE(secondsSince(start), 0.4);
    start = std::chrono::steady_clock::now();
    n->onScan(scanAt(t0 + 0.1));  // no newer transform since: decided at once, laser only
    EXPECT_LT(secondsSince(start), 0.25);
    EXPECT_EQ(n->counters().odom_missing, 2u);
    n->tfBuffer().setTransform(odomAt(t0 + 0.15), "test");  // /tf is back
    start = std::chrono::steady_clock::now();
    n->onScan(scanAt(ros::Time::now().toSec()));  // after the newest transform: waits again
    EXPECT_GE(secondsSince(start), 0.2);
}

TEST_F(ScanFilterNodeTest, TheWaitIsCappedByWhatTheScanQueueAbsorbs) {
    ros::param::set("/capnode/tf_wait", 3.0);
    ros::param::set("/capnode/queue_size", 3);
    auto n = node("capnode");
    const double t0 = ros::Time::now().toSec();
    // Scans 0.1 s apart, stamped long ago (no wait: their deadline is past): the pace is known.
    for (int i = 0; i < 5; ++i) n->onScan(scanAt(t0 - 10.0 + 0.1 * i));
    n->tfBuffer().setTransform(odomAt(t0 - 5.0), "test");  // /tf alive, but late
    const auto start = std::chrono::steady_clock::now();
    n->onScan(scanAt(t0));  // waits (3 - 1) x 0.1 s = 0.2 s, not 3 s
    EXPECT_GE(secondsSince(start), 0.15);
    EXPECT_LT(secondsSince(start), 1.5);
}

// Issue 38: before two scans have come, the pace is the scan's own scan_time: the first scan of
// a laser-only stream waits (queue_size - 1) x scan_time, not ~tf_wait, while scans queue up.
TEST_F(ScanFilterNodeTest, TheFirstScansWaitIsCappedByItsOwnScanTime) {
    ros::param::set("/firstnode/tf_wait", 3.0);
    ros::param::set("/firstnode/queue_size", 3);
    auto n = node("firstnode");
    auto m = boost::make_shared<sensor_msgs::LaserScan>(roomScan(ros::Time::now().toSec()));
    m->scan_time = 0.1f;
    const auto start = std::chrono::steady_clock::now();
    n->onScan(m);  // no transform ever: waits (3 - 1) x 0.1 s = 0.2 s, not 3 s
    EXPECT_GE(secondsSince(start), 0.15);
    EXPECT_LT(secondsSince(start), 1.5);
    EXPECT_EQ(n->counters().odom_missing, 1u);
}

TEST_F(ScanFilterNodeTest, AScanBeforeTheFirstTransformDoesNotWaitForIt) {
    ros::param::set("/earlynode/tf_wait", 2.0);
    auto n = node("earlynode");
    const double t0 = ros::Time::now().toSec();
    n->tfBuffer().setTransform(odomAt(t0 + 5.0), "test");
    // 5 s before the first transform: no transform will ever come for it, so the scan is decided
    // at once (laser only) instead of holding the scans behind it for ~tf_wait = 2 s.
    const auto start = std::chrono::steady_clock::now();
    n->onScan(scanAt(t0));
    EXPECT_LT(secondsSince(start), 1.0);
    EXPECT_EQ(n->counters().odom_missing, 1u);
    n->onScan(scanAt(t0 + 4.5));  // within the edge rule's 1 s: takes the first transform
    EXPECT_EQ(n->counters().odom_missing, 1u);
}

TEST_F(ScanFilterNodeTest, OdometryTopicIsInterpolatedAtTheScanStamp) {
    ros::param::set("/odomnode/odom", std::string("topic"));
    auto n = node("odomnode");
    for (double s : {10.0, 10.2}) {
        auto o = boost::make_shared<nav_msgs::Odometry>();
        o->header.stamp.fromSec(s);
        o->pose.pose.orientation.w = 1.0;
        n->onOdometry(o);
    }
    n->onScan(scanAt(10.1));
    EXPECT_EQ(n->counters().odom_missing, 0u);
    n->onScan(scanAt(12.0));  // 1.8 s after the last sample: unknown
    EXPECT_EQ(n->counters().odom_missing, 1u);
}

TEST_F(ScanFilterNodeTest, PublishesKeptScansAndStats) {
    ros::param::set("/pubnode/odom", std::string("none"));
    auto n = node("pubnode");
    ros::NodeHandle nh("/pubnode_ns");
    int received = 0;
    auto sub = nh.subscribe<sensor_msgs::LaserScan>(
        "scan_filtered", 10, [&](const sensor_msgs::LaserScan::ConstPtr&) { ++received; });
    waitForPublisher(sub);
    n->onScan(scanAt(1.0));
    spinUntil([&] { return received > 0; }, 200);
    EXPECT_EQ(received, 1);
    const auto s = n->stats();
    std::map<std::string, std::string> kv;
    for (const auto& v : s.values) kv[v.key] = v.value;
    for (const char* k : {"scans_in", "scans_kept", "dropped_pct", "points_removed", "out_of_order",
                          "odom_missing", "resets", "latency_p50_us", "latency_p99_us",
                          "latency_max_us", "work_p50_us", "work_p99_us", "work_max_us"})
        EXPECT_EQ(kv.count(k), 1u) << k;
    EXPECT_EQ(kv["scans_in"], "1");
    EXPECT_EQ(kv["scans_kept"], "1");
    EXPECT_EQ(kv["odom_missing"], "0");  // ~odom none: nothing expected
}

// ~next_scan: true (one scan of latency): a keyframe is published when its frame's next scan
// comes, and the last one when the node finishes (shutting down), not lost.
TEST_F(ScanFilterNodeTest, NextScanPublishesEachKeyframeOneScanLater) {
    ros::param::set("/nextnode/odom", std::string("none"));
    ros::param::set("/nextnode/next_scan", true);
    auto n = node("nextnode");
    ros::NodeHandle nh("/nextnode_ns");
    std::vector<double> stamps;
    auto sub = nh.subscribe<sensor_msgs::LaserScan>("scan_filtered", 10,
                                                    [&](const sensor_msgs::LaserScan::ConstPtr& m) {
                                                        stamps.push_back(m->header.stamp.toSec());
                                                    });
    waitForPublisher(sub);
    const auto spinFor = [&](std::size_t want) {
        spinUntil([&] { return stamps.size() >= want; }, 100);
    };
    n->onScan(scanAt(1.0));
    spinFor(1);
    EXPECT_TRUE(stamps.empty());  // held for the next scan
    EXPECT_EQ(n->counters().scans_kept, 0u);
    n->onScan(scanAt(1.1));
    spinFor(1);
    ASSERT_EQ(stamps.size(), 1u);
    EXPECT_DOUBLE_EQ(stamps[0], 1.0);
    n->onScan(boost::make_shared<sensor_msgs::LaserScan>(roomScan(1.2, "laser", 181, 1.0)));
    n->finish();  // the moved scan's keyframe, without its next scan
    spinFor(2);
    ASSERT_EQ(stamps.size(), 2u);
    EXPECT_DOUBLE_EQ(stamps[1], 1.2);
    EXPECT_EQ(n->counters().scans_kept, 2u);
}

TEST_F(ScanFilterNodeTest, ABagLoopingResetsWithAWarning) {
    ros::param::set("/loopnode/odom", std::string("none"));
    auto n = node("loopnode");
    // A 1.5 s bag played with --loop: its stamps go back 1.5 s (>= ~reset_jump) each time.
    for (int loop = 0; loop < 3; ++loop)
        for (int i = 0; i < 16; ++i) n->onScan(scanAt(50.0 + 0.1 * i));
    EXPECT_EQ(n->counters().resets, 2u);
    EXPECT_EQ(n->counters().scans_in, 48u);
    EXPECT_EQ(n->counters().out_of_order, 0u);
}

// The track stage's pose of every scan, kept or dropped, on ~track_topic: the robot walking
// 5 cm a scan towards the room's front wall, without odometry, is tracked by the scans alone.
TEST_F(ScanFilterNodeTest, PublishesTheTrackedPoseOfEveryScan) {
    ros::param::set("/tracknode/odom", std::string("none"));
    auto n = node("tracknode");
    ros::NodeHandle nh("/tracknode_ns");
    std::vector<nav_msgs::Odometry> poses;
    auto sub = nh.subscribe<nav_msgs::Odometry>(
        "tracked_odom", 50, [&](const nav_msgs::Odometry::ConstPtr& m) { poses.push_back(*m); });
    waitForPublisher(sub);
    for (int i = 0; i < 10; ++i)
        n->onScan(boost::make_shared<sensor_msgs::LaserScan>(
            roomScan(2.0 + 0.1 * i, "laser", 181, 0.05 * i)));
    spinUntil([&] { return poses.size() >= 10; }, 200);
    ASSERT_EQ(poses.size(), 10u);  // every scan, not only the kept ones
    EXPECT_LT(n->counters().scans_kept, 10u);
    EXPECT_EQ(poses.back().header.frame_id, "odom");
    EXPECT_EQ(poses.back().child_frame_id, "base_link");
    EXPECT_DOUBLE_EQ(poses.back().header.stamp.toSec(), 2.9);
    EXPECT_NEAR(poses.back().pose.pose.position.x, 0.45, 0.02);
    EXPECT_NEAR(poses.back().pose.pose.position.y, 0.0, 0.02);
}

// Scans that never reach the stages (no beams, a NaN increment, every range NaN) publish no
// tracked pose and do not stop the node; the next good scan is tracked.
TEST_F(ScanFilterNodeTest, AnUnusableScanPublishesNoTrackedPose) {
    ros::param::set("/badtrack/odom", std::string("none"));
    auto n = node("badtrack");
    ros::NodeHandle nh("/badtrack_ns");
    int received = 0;
    auto sub = nh.subscribe<nav_msgs::Odometry>(
        "tracked_odom", 50, [&](const nav_msgs::Odometry::ConstPtr&) { ++received; });
    waitForPublisher(sub);
    auto empty = boost::make_shared<sensor_msgs::LaserScan>(roomScan(3.0));
    empty->ranges.clear();
    auto nan_step = boost::make_shared<sensor_msgs::LaserScan>(roomScan(3.1));
    nan_step->angle_increment = std::numeric_limits<float>::quiet_NaN();
    auto blind = boost::make_shared<sensor_msgs::LaserScan>(roomScan(3.2));
    for (float& r : blind->ranges) r = std::numeric_limits<float>::quiet_NaN();
    for (const auto& m : {empty, nan_step}) n->onScan(m);
    n->onScan(blind);
    n->onScan(scanAt(3.3));
    spinUntil([&] { return received >= 2; }, 100);
    EXPECT_EQ(n->counters().scans_in, 4u);
    EXPECT_GE(n->counters().scans_skipped, 2u);
    EXPECT_LE(received, 2);  // the blind scan may be tracked (its prior), the unusable ones never
    EXPECT_GE(received, 1);  // the good scan
}

TEST_F(ScanFilterNodeTest, TrackTfIsRefusedWhereItWouldReadItsOwnTransform) {
    ros::param::set("/tftrack1/track_tf", true);  // ~odom: tf (the default) reads odom -> base
    EXPECT_EQ(refusedKey("tftrack1"), "track_tf");
    ros::param::set("/tftrack2/track_tf", std::string("yes"));
    EXPECT_EQ(refusedKey("tftrack2"), "track_tf");
    ros::param::set("/tftrack3/odom", std::string("none"));
    ros::param::set("/tftrack3/track_tf", true);
    ros::param::set("/tftrack3/pipeline", std::string("distance,view_keyframe"));
    EXPECT_EQ(refusedKey("tftrack3"), "track_tf");  // no track stage to publish
    ros::param::set("/tftrack4/odom", std::string("none"));
    ros::param::set("/tftrack4/track_tf", true);
    EXPECT_EQ(refusedKey("tftrack4"), "");
}

// ~track_tf with ~odom: none: the track is broadcast as odom -> base_link at each scan's stamp
// (the node's own tf listener hears it).
TEST_F(ScanFilterNodeTest, TrackTfBroadcastsTheTrackedPose) {
    ros::param::set("/tfbcast/odom", std::string("none"));
    ros::param::set("/tfbcast/track_tf", true);
    auto n = node("tfbcast");
    for (int i = 0; i < 3; ++i)
        n->onScan(boost::make_shared<sensor_msgs::LaserScan>(
            roomScan(4.0 + 0.1 * i, "laser", 181, 0.05 * i)));
    const ros::Time last(4.2);
    spinUntil([&] { return n->tfBuffer().canTransform("odom", "base_link", last); }, 200);
    ASSERT_TRUE(n->tfBuffer().canTransform("odom", "base_link", last));
    const auto t = n->tfBuffer().lookupTransform("odom", "base_link", last);
    EXPECT_NEAR(t.transform.translation.x, 0.10, 0.02);
}

}  // namespace
