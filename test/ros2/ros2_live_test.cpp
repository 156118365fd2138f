// kfd_ros2 live, with independent peers on 127.0.0.1 only: a Fast DDS participant set up as
// rmw_fastrtps (Fast CDR encoding) publishes a real log's scans and odometry on rt/scan, rt/odom
// and rt/tf_static; what comes back on rt/scan_filtered must be what kfd-filter keeps offline
// from the same log (stamps and ranges, NaN equal), with nothing lost, at 10x real time and at
// 40 scans/s. Every wait is bounded.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>

#include "ros2/fastdds_peer.h"
#include "ros2/node_process.h"
#include "ros2/same_ranges.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using kfd_test::FastDdsPeer;
using kfd_test::NodeProcess;
using kfd_test::waitUntil;

const std::string kBag = std::string(KFD_DATASETS_DIR) + "/fr079/fr079.orig.bag";
constexpr double kLogSeconds = 60.0;  // the log's first minute (about 280 scans)

int domainId() { return 100 + static_cast<int>(getpid() % 100); }

std::string tmpDir(const std::string& name) {
    const fs::path d =
        fs::temp_directory_path() / ("kfd_ros2_" + name + "_" + std::to_string(getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d.string();
}

double stampOf(const std_msgs::Header& h) { return h.stamp.sec + 1e-9 * h.stamp.nsec; }

// kfd-filter's kept scans of the bag, offline, read back from its .db3 output with sqlite3 and
// Fast CDR (not with kfd's reader).
std::map<double, sensor_msgs::LaserScan> offlineKept(const std::string& dir,
                                                     const std::string& odom) {
    const std::string out = dir + "/offline.db3";
    const std::string cmd = std::string(KFD_FILTER_EXE) + " -i " + kBag + " -o " + out +
                            " --odom-topic " + odom + " > /dev/null 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::map<double, sensor_msgs::LaserScan> kept;
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open_v2(out.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(db,
                       "SELECT m.data FROM messages m JOIN topics t ON m.topic_id = t.id "
                       "WHERE t.name = '/scan' ORDER BY m.timestamp",
                       -1, &st, nullptr);
    while (st && sqlite3_step(st) == SQLITE_ROW) {
        const auto* p = static_cast<const char*>(sqlite3_column_blob(st, 0));
        std::vector<char> bytes(p, p + sqlite3_column_bytes(st, 0));
        eprosima::fastcdr::FastBuffer fb(bytes.data(), bytes.size());
        eprosima::fastcdr::Cdr c(fb, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN,
                                 eprosima::fastcdr::Cdr::DDS_CDR);
        c.read_encapsulation();
        sensor_msgs::LaserScan m;
        kfd_test::get(c, m);
        kept[stampOf(m.header)] = m;
    }
    sqlite3_finalize(st);
    sqlite3_close(db);
    return kept;
}

using kfd_test::sameRanges;

// What a run gave back.
struct LiveRun {
    std::size_t published = 0;  // scans the peer wrote
    double last_stamp = 0.0;    // the last of them
    std::map<double, sensor_msgs::LaserScan> received;
    std::string log;
    int exit_code = -1;
};

// Paces the log's first kLogSeconds: at `speed` x real time, or (speed <= 0) scans 25 ms apart
// (40 Hz) with the odometry between them in its place.
class Pacer {
  public:
    Pacer(double speed, double first) : speed_(speed), first_(first) {}
    void waitFor(double stamp, std::size_t scans_before) {
        const double at = speed_ > 0 ? (stamp - first_) / speed_ : 0.025 * double(scans_before);
        std::this_thread::sleep_until(start_ + std::chrono::duration<double>(at));
    }

  private:
    double speed_, first_;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

LiveRun runLive(const std::string& dir, double speed, const std::vector<std::string>& extra) {
    LiveRun run;
    const int domain = domainId();
    std::vector<std::string> args{"--ros-args", "-p", "localhost_only:=true", "-p",
                                  "domain_id:=" + std::to_string(domain)};
    args.insert(args.end(), extra.begin(), extra.end());
    NodeProcess node(KFD_ROS2_EXE, args, dir + "/node.log");
    EXPECT_TRUE(node.started());
    FastDdsPeer peer(domain);
    std::mutex mu;
    peer.reader<sensor_msgs::LaserScan>("rt/scan_filtered", "sensor_msgs::msg::dds_::LaserScan_",
                                        [&](sensor_msgs::LaserScan& m) {
                                            std::lock_guard<std::mutex> l(mu);
                                            run.received[stampOf(m.header)] = m;
                                        });
    auto* scan_w =
        peer.writer<sensor_msgs::LaserScan>("rt/scan", "sensor_msgs::msg::dds_::LaserScan_", true);
    auto* odom_w =
        peer.writer<nav_msgs::Odometry>("rt/odom", "nav_msgs::msg::dds_::Odometry_", true);
    auto* tfs_w = peer.writer<tf2_msgs::TFMessage>("rt/tf_static",
                                                   "tf2_msgs::msg::dds_::TFMessage_", true, true);
    const bool odometry = std::find(extra.begin(), extra.end(), "odom:=topic") != extra.end();
    const bool matched = waitUntil(20.0, [&] {
        return kfd_test::matched(scan_w) && (!odometry || kfd_test::matched(odom_w)) &&
               kfd_test::matched(tfs_w);
    });
    EXPECT_TRUE(matched) << "the node never matched the peer's writers\n" << node.log();
    if (!matched) return run;
    // The writers know the node's readers; give the readers the same moment to know the writers
    // (a best-effort reader drops samples of a writer it has not discovered yet).
    std::this_thread::sleep_for(std::chrono::seconds(1));
    rosbag::Bag bag(kBag);
    rosbag::View view(bag, rosbag::TopicQuery({"/scan", "/odom", "/tf_static"}));
    const double first = view.getBeginTime().toSec();
    Pacer pace(speed, first);
    for (const rosbag::MessageInstance& mi : view) {
        if (mi.getTime().toSec() > first + kLogSeconds) break;
        if (auto tf = mi.instantiate<tf2_msgs::TFMessage>()) {
            tfs_w->write(tf.get());
            tfs_w->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(5.0));
        } else if (auto o = mi.instantiate<nav_msgs::Odometry>(); o && odometry) {
            pace.waitFor(mi.getTime().toSec(), run.published);
            EXPECT_TRUE(odom_w->write(o.get()));
        } else if (auto s = mi.instantiate<sensor_msgs::LaserScan>()) {
            pace.waitFor(mi.getTime().toSec(), run.published);
            EXPECT_TRUE(scan_w->write(s.get())) << "scan " << run.published;
            ++run.published;
            run.last_stamp = stampOf(s->header);
        }
    }
    scan_w->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(5.0));
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    run.exit_code = node.stop(10.0);
    waitUntil(2.0, [] { return false; });  // the node's last keyframe on its way
    run.log = node.log();
    return run;
}

// The live run against kfd-filter offline: every scan received, the kept ones identical up to
// 2 s of log before the end (the last scans' decisions need scans the run never sent).
void expectSameAsOffline(const LiveRun& run, const std::map<double, sensor_msgs::LaserScan>& kept) {
    ASSERT_GT(run.published, 200u);
    EXPECT_EQ(run.exit_code, 0) << run.log;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(run.log, m, std::regex(R"(stopped: (\d+) of (\d+) scans kept)")))
        << run.log;
    EXPECT_EQ(std::stoul(m[2]), run.published) << "scans lost on the way in\n" << run.log;
    const double cutoff = run.last_stamp - 2.0;
    std::size_t compared = 0;
    for (const auto& [t, scan] : kept) {
        if (t > cutoff) break;
        const auto it = run.received.find(t);
        ASSERT_NE(it, run.received.end())
            << "offline kept the scan at " << t << " s, live did not\n"
            << run.log;
        EXPECT_TRUE(sameRanges(it->second.ranges, scan.ranges)) << "scan at " << t << " s";
        EXPECT_EQ(it->second.header.frame_id, scan.header.frame_id);
        ++compared;
    }
    std::size_t live_before = 0;
    for (const auto& [t, scan] : run.received) live_before += t <= cutoff;
    EXPECT_EQ(live_before, compared) << "live kept scans that offline dropped";
    EXPECT_GT(compared, 10u);
}

TEST(Ros2Live, FastDdsPeerAtTenTimesRealTimeGetsWhatKfdFilterKeepsOffline) {
    const std::string dir = tmpDir("x10");
    const auto kept = offlineKept(dir, "/odom");
    const LiveRun run = runLive(dir, 10.0, {"-p", "odom:=topic", "-p", "scan_qos:=reliable"});
    expectSameAsOffline(run, kept);
}

TEST(Ros2Live, FastDdsPeerAtFortyScansPerSecondGetsWhatKfdFilterKeepsOffline) {
    const std::string dir = tmpDir("40hz");
    const auto kept = offlineKept(dir, "/odom");
    const LiveRun run = runLive(dir, 0.0, {"-p", "odom:=topic"});
    expectSameAsOffline(run, kept);
}

TEST(Ros2Live, LaserOnlyMatchesKfdFilterWithoutOdometry) {
    const std::string dir = tmpDir("none");
    const auto kept = offlineKept(dir, "none");
    const LiveRun run = runLive(dir, 10.0, {"-p", "odom:=none"});
    expectSameAsOffline(run, kept);
}

}  // namespace
