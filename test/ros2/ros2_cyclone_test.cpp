// kfd_ros2 live with a second, independent DDS: a Cyclone DDS 0.10 participant (the DDS of
// rmw_cyclonedds_cpp), its LaserScan type compiled by idlc from ros2_laser_scan.idl, publishes a
// real log's scans on rt/scan and reads rt/scan_filtered, 127.0.0.1 only. What comes back must
// be what kfd-filter keeps offline, laser only (stamps and ranges, NaN equal). Bounded waits.
#include <dds/dds.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <regex>
#include <thread>

#include "kfd/io/ros2_message.h"
#include "ros2/node_process.h"
#include "ros2/same_ranges.h"
#include "ros2_laser_scan.h"

namespace {

namespace fs = std::filesystem;
using Scan = sensor_msgs_msg_dds__LaserScan_;

const std::string kBag = std::string(KFD_DATASETS_DIR) + "/fr079/fr079.orig.bag";
constexpr std::size_t kScans = 150;

// Cyclone on 127.0.0.1 only, unicast discovery (as in ../shared/notes/platform.md).
const char* const kLoopback =
    "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface "
    "address=\"127.0.0.1\"/></Interfaces><AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>auto</ParticipantIndex><Peers><Peer address=\"127.0.0.1\"/>"
    "</Peers></Discovery></Domain></CycloneDDS>";

double stampOf(const std_msgs::Header& h) { return h.stamp.sec + 1e-9 * h.stamp.nsec; }

// kfd-filter's kept scans, laser only, read back with kfd's own decoder this time (the Fast DDS
// test reads them with Fast CDR).
std::map<double, sensor_msgs::LaserScan> offline(const std::string& dir) {
    const std::string out = dir + "/offline.bag";
    const std::string cmd = std::string(KFD_FILTER_EXE) + " -i " + kBag + " -o " + out +
                            " --odom-topic none > /dev/null 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    std::map<double, sensor_msgs::LaserScan> kept;
    rosbag::Bag bag(out);
    for (const auto& mi : rosbag::View(bag, rosbag::TopicQuery(std::string("/scan"))))
        if (auto s = mi.instantiate<sensor_msgs::LaserScan>()) kept[stampOf(s->header)] = *s;
    return kept;
}

struct CyclonePeer {
    dds_entity_t participant = 0, writer = 0, reader = 0;
    explicit CyclonePeer(int domain) {
        dds_create_domain(static_cast<dds_domainid_t>(domain), kLoopback);
        participant = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
        dds_qos_t* q = dds_create_qos();
        dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
        dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
        const dds_entity_t in = dds_create_topic(participant, &sensor_msgs_msg_dds__LaserScan__desc,
                                                 "rt/scan", nullptr, nullptr);
        const dds_entity_t out =
            dds_create_topic(participant, &sensor_msgs_msg_dds__LaserScan__desc, "rt/scan_filtered",
                             nullptr, nullptr);
        writer = dds_create_writer(participant, in, q, nullptr);
        reader = dds_create_reader(participant, out, q, nullptr);
        dds_delete_qos(q);
    }
    ~CyclonePeer() { dds_delete(participant); }
    bool matched() const {
        dds_publication_matched_status_t w{};
        dds_subscription_matched_status_t r{};
        dds_get_publication_matched_status(writer, &w);
        dds_get_subscription_matched_status(reader, &r);
        return w.current_count > 0 && r.current_count > 0;
    }
    void write(sensor_msgs::LaserScan& m) {
        Scan s{};
        s.header.stamp.sec = static_cast<int32_t>(m.header.stamp.sec);
        s.header.stamp.nanosec = m.header.stamp.nsec;
        s.header.frame_id = m.header.frame_id.data();
        s.angle_min = m.angle_min;
        s.angle_max = m.angle_max;
        s.angle_increment = m.angle_increment;
        s.time_increment = m.time_increment;
        s.scan_time = m.scan_time;
        s.range_min = m.range_min;
        s.range_max = m.range_max;
        s.ranges = {static_cast<uint32_t>(m.ranges.size()), static_cast<uint32_t>(m.ranges.size()),
                    m.ranges.data(), false};
        s.intensities = {static_cast<uint32_t>(m.intensities.size()),
                         static_cast<uint32_t>(m.intensities.size()), m.intensities.data(), false};
        EXPECT_EQ(dds_write(writer, &s), DDS_RETCODE_OK);
    }
    /// The USER_DATA of the writer the reader matched (kfd_ros2's scan_filtered), as text.
    std::string matchedWriterUserData() const {
        dds_instance_handle_t h[4];
        if (dds_get_matched_publications(reader, h, 4) < 1) return "";
        dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(reader, h[0]);
        if (!e) return "";
        void* v = nullptr;
        std::size_t n = 0;
        std::string text;
        if (dds_qget_userdata(e->qos, &v, &n) && v) text.assign(static_cast<char*>(v), n);
        dds_free(v);
        dds_builtintopic_free_endpoint(e);
        return text;
    }
    // Everything the node has sent back so far, into `got` by stamp.
    void take(std::map<double, std::vector<float>>& got) {
        void* samples[32] = {nullptr};
        dds_sample_info_t infos[32];
        const dds_return_t n = dds_take(reader, samples, infos, 32, 32);
        for (dds_return_t i = 0; i < n; ++i) {
            if (!infos[i].valid_data) continue;
            const auto* s = static_cast<const Scan*>(samples[i]);
            const double t = s->header.stamp.sec + 1e-9 * s->header.stamp.nanosec;
            got[t].assign(s->ranges._buffer, s->ranges._buffer + s->ranges._length);
        }
        if (n > 0) dds_return_loan(reader, samples, n);
    }
};

using kfd_test::sameRanges;

TEST(Ros2Cyclone, CyclonePeerGetsWhatKfdFilterKeepsOffline) {
    const fs::path dir =
        fs::temp_directory_path() / ("kfd_ros2_cyclone_" + std::to_string(getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const auto kept = offline(dir.string());
    const int domain = 100 + static_cast<int>((getpid() + 37) % 100);
    kfd_test::NodeProcess node(KFD_ROS2_EXE,
                               {"--ros-args", "-p", "localhost_only:=true", "-p",
                                "domain_id:=" + std::to_string(domain), "-p", "odom:=none"},
                               (dir / "node.log").string());
    ASSERT_TRUE(node.started());
    CyclonePeer peer(domain);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!peer.matched() && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(peer.matched()) << "Cyclone and kfd_ros2 never matched\n" << node.log();
    std::this_thread::sleep_for(std::chrono::seconds(1));  // the node's side of the discovery
    // Jazzy reads the type hash from USER_DATA (and warns when it is missing).
    EXPECT_EQ(peer.matchedWriterUserData(),
              "typehash=RIHS01_64c191398013af96509d518dac71d5164f9382553fce5c1f8cca5be7924bd828;");
    std::map<double, std::vector<float>> got;
    rosbag::Bag bag(kBag);
    std::size_t sent = 0;
    double last = 0.0;
    for (const auto& mi : rosbag::View(bag, rosbag::TopicQuery(std::string("/scan")))) {
        auto s = mi.instantiate<sensor_msgs::LaserScan>();
        if (!s || sent == kScans) break;
        peer.write(*s);
        last = stampOf(s->header);
        ++sent;
        std::this_thread::sleep_for(std::chrono::milliseconds(25));  // 40 scans/s
        peer.take(got);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    EXPECT_EQ(node.stop(10.0), 0) << node.log();
    const auto drained = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (std::chrono::steady_clock::now() < drained) {
        peer.take(got);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    const std::string log = node.log();
    std::smatch m;
    ASSERT_TRUE(std::regex_search(log, m, std::regex(R"(stopped: \d+ of (\d+) scans kept)")))
        << log;
    EXPECT_EQ(std::stoul(m[1]), sent) << "scans lost on the way in\n" << log;
    std::size_t compared = 0, live_before = 0;
    for (const auto& [t, scan] : kept) {
        if (t > last - 2.0) break;
        const auto it = got.find(t);
        ASSERT_NE(it, got.end()) << "offline kept the scan at " << t << " s, live did not\n" << log;
        EXPECT_TRUE(sameRanges(it->second, scan.ranges)) << "scan at " << t << " s";
        ++compared;
    }
    for (const auto& [t, r] : got) live_before += t <= last - 2.0;
    EXPECT_EQ(live_before, compared) << "live kept scans that offline dropped";
    EXPECT_GT(compared, 10u);
}

}  // namespace
