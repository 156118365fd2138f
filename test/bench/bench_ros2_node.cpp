// kfd_bench_ros2_node: the ROS 2 node's own work per scan, without DDS: each scan of a log as the
// CDR a driver sends, through kfd::ros2::Ros2Node (decode, the live front end, encode of what is
// published), its odometry as nav_msgs/Odometry samples just after the scan. Prints the thread
// CPU time per scan (p50, p99, max; µs) over the log, and how many scans were kept.
//   kfd_bench_ros2_node LOG [REPEATS]   (default: the bundled 1081-beam simulated 40 Hz log)
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "kfd/io/open_source.h"
#include "kfd/io/ros2_message.h"
#include "kfd/mrpt/config.h"
#include "kfd/ros2/ros2_node.h"

namespace {

double threadCpuMicros() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return 1e6 * double(t.tv_sec) + 1e-3 * double(t.tv_nsec);
}

sensor_msgs::LaserScan toMessage(const mrpt::obs::CObservation2DRangeScan& o, double t) {
    sensor_msgs::LaserScan m;
    m.header.stamp.fromSec(t);
    m.header.frame_id = "laser";
    const std::size_t n = o.getScanSize();
    m.angle_min = static_cast<float>(-0.5 * o.aperture);
    m.angle_increment = static_cast<float>(o.aperture / double(n - 1));
    m.angle_max = static_cast<float>(0.5 * o.aperture);
    m.range_min = 0.05f;
    m.range_max = o.maxRange;
    m.ranges.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        m.ranges[i] =
            o.getScanRangeValidity(i) ? o.getScanRange(i) : std::numeric_limits<float>::quiet_NaN();
    return m;
}

nav_msgs::Odometry odometry(double t, const kfd::Pose2D& p) {
    nav_msgs::Odometry m;
    m.header.stamp.fromSec(t);
    m.header.frame_id = "odom";
    m.child_frame_id = "base_link";
    m.pose.pose.position.x = p.x;
    m.pose.pose.position.y = p.y;
    m.pose.pose.orientation.z = std::sin(0.5 * p.phi);
    m.pose.pose.orientation.w = std::cos(0.5 * p.phi);
    return m;
}

}  // namespace

int main(int argc, char** argv) {
    const std::string log =
        argc > 1 ? argv[1] : std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";
    const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
    kfd::ros2::Ros2Config c;
    c.pipeline = kfd::kfdDefaults();
    c.odometry = kfd::ros2::Ros2Config::Odometry::Topic;
    std::vector<double> cpu;
    std::size_t kept = 0, scans = 0, beams = 0;
    for (int r = 0; r < repeats; ++r) {
        kfd::ros2::Ros2Outputs out;
        out.scan_filtered = [&](const kfd::ros2::Bytes&) { ++kept; };
        kfd::ros2::Ros2Node node(c, out, [] { return 0.0; });
        auto src = kfd::openSource(log);
        for (kfd::SourceEntry e; src->next(e);) {
            e.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
                const double t = 1000.0 * r + mrpt::Clock::toDouble(s->timestamp) -
                                 std::floor(mrpt::Clock::toDouble(s->timestamp) / 1000.0) * 1000.0;
                const auto scan = kfd::encodeRos2(toMessage(*s, t));
                const auto odom =
                    kfd::encodeRos2(odometry(t + 1e-3, e.odometry.value_or(kfd::Pose2D{})));
                beams = s->getScanSize();
                const double start = threadCpuMicros();
                node.onScan(scan.data(), scan.size());
                node.onOdometry(odom.data(), odom.size());  // the sample after: filtered now
                cpu.push_back(threadCpuMicros() - start);
                ++scans;
            });
        }
        node.finish();
    }
    std::sort(cpu.begin(), cpu.end());
    const auto pct = [&](double p) {
        return cpu.empty() ? 0.0
                           : cpu[std::min(cpu.size() - 1, std::size_t(p / 100.0 * cpu.size()))];
    };
    std::printf(
        "%s: %zu scans of %zu beams (%d passes), %zu kept; kfd_ros2's own work per scan "
        "(thread CPU, decode + filter + encode): p50 %.0f us, p99 %.0f us, max %.0f us\n",
        log.c_str(), scans, beams, repeats, kept, pct(50), pct(99), cpu.empty() ? 0.0 : cpu.back());
    return 0;
}
