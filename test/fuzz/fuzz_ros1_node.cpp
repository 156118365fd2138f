// libFuzzer target: the ROS 1 node's callbacks (kfd::ros1::ScanFilterNode, what roscpp hands
// kfd_node and the nodelet) fed arbitrary messages. The process starts a roscore of its own on
// a free loopback port (killed with it), with simulated time. The input's first byte picks the
// node's odometry (tf, topic, none) and next_scan; then records [kind u8][size u16 LE][bytes]:
// kind % 5 = 0 a LaserScan, 1 an Odometry, 2 a tf2_msgs/TFMessage (into the node's tf buffer,
// as its listener does), each in ROS 1's wire format (bytes roscpp cannot read are skipped, as
// roscpp drops them), 3 the clock moves by the next byte x 10 ms (back when the byte is odd),
// 4 the stats are published. Each input gets a fresh node and ends with stop() (a signal's
// path). Whatever the messages, nothing may crash, throw out of a callback, leak or hang.
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <mrpt/config/CConfigFileMemory.h>
#include <ros/ros.h>
#include <ros/serialization.h>
#include <tf2_msgs/TFMessage.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <string>
#include <thread>

#include "kfd/mrpt/allocation_limit.h"
#include "kfd/mrpt/config.h"
#include "kfd/ros1/scan_filter_node.h"

namespace {

int freePort() {
    const int s = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bind(s, reinterpret_cast<sockaddr*>(&a), sizeof(a));
    socklen_t n = sizeof(a);
    getsockname(s, reinterpret_cast<sockaddr*>(&a), &n);
    close(s);
    return ntohs(a.sin_port);
}

// A message of type M from ROS 1's wire bytes; false when roscpp could not read them. roscpp
// only delivers a message whose bytes all came: an array's declared length beyond the bytes
// there are is refused here (kfd's allocation bound) before roscpp's deserialiser sizes it.
template <class M>
bool fromWire(const std::uint8_t* data, std::size_t n, M& m) {
    try {
        const kfd::ScopedAllocationLimit limit(n + 4096);
        ros::serialization::IStream in(const_cast<std::uint8_t*>(data), std::uint32_t(n));
        ros::serialization::deserialize(in, m);
        return true;
    } catch (const std::exception&) {  // overrun, or an allocation beyond kfd's bound
        return false;
    }
}

void startRos() {
    const std::string port = std::to_string(freePort());
    const std::string home = "/tmp/kfd_fuzz_ros1_" + std::to_string(getpid());
    setenv("ROS_MASTER_URI", ("http://127.0.0.1:" + port).c_str(), 1);
    setenv("ROS_IP", "127.0.0.1", 1);
    setenv("ROS_HOME", home.c_str(), 1);
    setenv("ROS_LOG_DIR", (home + "/log").c_str(), 1);
    if (fork() == 0) {
        setpgid(0, 0);
        prctl(PR_SET_PDEATHSIG, SIGINT);  // the fuzzer's end takes roscore along
        freopen("/dev/null", "w", stdout);
        freopen("/dev/null", "w", stderr);
        execlp("roscore", "roscore", "-p", port.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    int argc = 0;
    ros::init(argc, nullptr, "fuzz_ros1_node", ros::init_options::NoSigintHandler);
    for (int i = 0; i < 300 && !ros::master::check(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (!ros::master::check()) std::abort();  // no roscore: nothing to fuzz
    ros::param::set("/use_sim_time", true);
    ros::start();
    ros::console::set_logger_level(ROSCONSOLE_DEFAULT_NAME, ros::console::levels::Fatal);
}

// kfd's defaults with every keyframe held for its next scan.
const kfd::Pipeline::Params& nextScan() {
    static const kfd::Pipeline::Params p = kfd::loadIni(mrpt::config::CConfigFileMemory(
        std::string("[KFD]\n[KFD.evidence_denoise]\nnext_scan = true\n")));
    return p;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    startRos();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    kfd::ros1::NodeConfig c;
    c.pipeline = kfd::kfdDefaults();
    c.odometry = data[0] % 3 == 0   ? kfd::ros1::NodeConfig::Odometry::Tf
                 : data[0] % 3 == 1 ? kfd::ros1::NodeConfig::Odometry::Topic
                                    : kfd::ros1::NodeConfig::Odometry::None;
    if (data[0] & 4) c.pipeline = nextScan();
    c.tf_wait = 0.0005;  // each scan waits at most 1 ms of wall time (the clock stands still)
    c.queue_size = 4;
    double clock = 1000.0;
    ros::Time::setNow(ros::Time(clock));
    kfd::ros1::ScanFilterNode node(ros::NodeHandle("/fuzz"), ros::NodeHandle("/fuzz/kfd"), c);
    std::size_t at = 1;
    while (at + 3 <= size) {
        const unsigned kind = data[at] % 5;
        const std::size_t n =
            std::min<std::size_t>(data[at + 1] | (data[at + 2] << 8), size - at - 3);
        const std::uint8_t* msg = data + at + 3;
        at += 3 + n;
        if (kind == 0) {
            auto m = boost::make_shared<sensor_msgs::LaserScan>();
            if (fromWire(msg, n, *m)) node.onScan(m);
        } else if (kind == 1) {
            auto m = boost::make_shared<nav_msgs::Odometry>();
            if (fromWire(msg, n, *m)) node.onOdometry(m);
        } else if (kind == 2) {
            tf2_msgs::TFMessage m;
            if (fromWire(msg, n, m))
                for (const auto& t : m.transforms) {
                    try {
                        node.tfBuffer().setTransform(t, "fuzz");  // as tf2_ros's listener
                    } catch (const std::exception&) {             // tf2 refusing it is tf2's matter
                    }
                }
        } else if (kind == 3 && n > 0) {
            clock += (msg[0] & 1 ? -0.01 : 0.01) * double(msg[0] >> 1);
            if (clock > 0.0) ros::Time::setNow(ros::Time(clock));
        } else if (kind == 4) {
            node.publishStats();
        }
    }
    node.stop();
    return 0;
}
