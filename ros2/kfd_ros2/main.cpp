// kfd_ros2: kfd on a ROS 2 robot, without ROS 2. A thin main over kfd::ros2::Ros2Node (the
// filter) and kfd::ros2::DdsBus (Fast DDS speaking ROS 2's wire protocol); docs/USAGE.md,
// "kfd_ros2 (ROS 2)".
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>

#include "kfd/ros2/dds_bus.h"
#include "kfd/ros2/ros2_node.h"

namespace {

using namespace kfd::ros2;

volatile std::sig_atomic_t g_stop = 0;
void onStop(int) { g_stop = 1; }

const char* const kUsage =
    "kfd_ros2: kfd's keyframe filter and denoiser as a ROS 2 node, without a ROS 2 install (it\n"
    "speaks ROS 2's DDS protocol through Fast DDS). Subscribes scan (sensor_msgs/LaserScan, best\n"
    "effort), odometry from tf (odom_frame -> base_frame) or the odom topic, and tf_static (the\n"
    "laser mount); publishes scan_filtered (the keyframes, removed points NaN; reliable),\n"
    "tracked_odom (with the track stage) and /diagnostics. Ctrl-C or SIGTERM stops it; a\n"
    "keyframe held for its next scan is published first.\n"
    "\n"
    "Usage: kfd_ros2 [--ros-args [-p NAME:=VALUE]... [-r FROM:=TO]... [--params-file F.yaml]]\n"
    "\n"
    "Options:\n"
    "  -h, --help               this text\n"
    "  --version                kfd's version\n"
    "  --ros-args               ROS 2's arguments follow (up to --)\n"
    "  -p, --param NAME:=VALUE  one parameter (below), its value read as YAML\n"
    "  -r, --remap FROM:=TO     a topic's name (scan, odom, scan_filtered, tracked_odom,\n"
    "                           /diagnostics, /tf, /tf_static), __ns:=/NS or __node:=NAME\n"
    "  --params-file FILE       a ROS 2 parameters YAML (NODE or /**: ros__parameters: ...)\n"
    "  --log-level LEVEL        accepted; kfd_ros2 logs what matters at any level\n"
    "\n"
    "Parameters:\n"
    "  config:=FILE             kfd's configuration (.ini or YAML; default: kfd's defaults)\n"
    "  STAGE.KEY:=VALUE         one kfd key (kfd-filter --list-keys), e.g. "
    "distance.max_range:=20;\n"
    "                           pipeline, selector and variant as they are\n"
    "  odom:=tf|topic|none      odometry (default tf)   odom_frame:=odom   base_frame:=base_link\n"
    "  tf_wait:=1.0             s a scan waits for the odometry after its stamp\n"
    "  removed_as:=nan|inf      queue_size:=10   reset_jump:=1.0   track_topic:=tracked_odom\n"
    "  scan_qos:=best_effort|reliable   stats_period:=1.0 (s between diagnostics)\n"
    "  domain_id:=N             (default $ROS_DOMAIN_ID, else 0)\n"
    "  localhost_only:=true     127.0.0.1 only (default: $ROS_LOCALHOST_ONLY=1)\n";

double steadySeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

double wallSeconds() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
        .count();
}

// The writers a node needs.
struct Writers {
    std::size_t scan = 0, track = 0, diagnostics = 0;
    bool has_track = false;
};

Writers advertise(DdsBus& bus, const Ros2Config& c) {
    Writers w;
    w.scan = bus.advertise(c.ddsTopic("scan_filtered"), "sensor_msgs/msg/LaserScan",
                           TopicQos{Reliability::Reliable, false, c.queue_size});
    w.diagnostics = bus.advertise(c.ddsTopic("/diagnostics"), "diagnostic_msgs/msg/DiagnosticArray",
                                  TopicQos{Reliability::Reliable, false, 10});
    if (!c.track_topic.empty()) {
        w.track = bus.advertise(c.ddsTopic(c.track_topic), "nav_msgs/msg/Odometry",
                                TopicQos{Reliability::Reliable, false, c.queue_size});
        w.has_track = true;
    }
    return w;
}

// What the node publishes waits here for the main thread: DDS's receive threads (where the
// node filters) never write, since a reliable write can block until its acknowledgments come
// in on those very threads.
class Outbox {
  public:
    void push(std::size_t writer, const Bytes& b) {
        {
            std::lock_guard<std::mutex> l(mutex_);
            queue_.emplace_back(writer, b);
        }
        cv_.notify_one();
    }
    /// Waits up to `ms` for something to publish, then publishes everything there is.
    void flush(DdsBus& bus, int ms) {
        std::deque<std::pair<std::size_t, Bytes>> out;
        {
            std::unique_lock<std::mutex> l(mutex_);
            cv_.wait_for(l, std::chrono::milliseconds(ms), [this] { return !queue_.empty(); });
            out.swap(queue_);
        }
        for (const auto& [writer, b] : out) failed_ += !bus.publish(writer, b);
    }
    /// Samples DDS refused to write.
    std::size_t failed() const { return failed_; }

  private:
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<std::pair<std::size_t, Bytes>> queue_;
    std::size_t failed_ = 0;  // the main thread's only
};

Ros2Outputs outputs(Outbox& box, const Writers& w) {
    Ros2Outputs o;
    o.scan_filtered = [&box, w](const Bytes& b) { box.push(w.scan, b); };
    o.diagnostics = [&box, w](const Bytes& b) { box.push(w.diagnostics, b); };
    if (w.has_track) o.track = [&box, w](const Bytes& b) { box.push(w.track, b); };
    o.log = [](const std::string& s) { std::fprintf(stderr, "[kfd_ros2] %s\n", s.c_str()); };
    return o;
}

// The inputs, best effort (any publisher's QoS matches) except tf_static (latched).
void subscribe(DdsBus& bus, Ros2Node& node, const Ros2Config& c) {
    const int depth = std::max(5, c.queue_size);
    bus.subscribe(c.ddsTopic("scan"), "sensor_msgs/msg/LaserScan",
                  TopicQos{c.scan_reliability, false, depth},
                  [&node](const std::uint8_t* d, std::size_t n) { node.onScan(d, n); });
    if (c.odometry == Ros2Config::Odometry::Topic)
        bus.subscribe(c.ddsTopic("odom"), "nav_msgs/msg/Odometry",
                      TopicQos{Reliability::BestEffort, false, 50},
                      [&node](const std::uint8_t* d, std::size_t n) { node.onOdometry(d, n); });
    if (c.odometry == Ros2Config::Odometry::Tf)
        bus.subscribe(c.ddsTopic("/tf"), "tf2_msgs/msg/TFMessage",
                      TopicQos{Reliability::BestEffort, false, 100},
                      [&node](const std::uint8_t* d, std::size_t n) { node.onTf(d, n, false); });
    bus.subscribe(c.ddsTopic("/tf_static"), "tf2_msgs/msg/TFMessage",
                  TopicQos{Reliability::Reliable, true, 100},
                  [&node](const std::uint8_t* d, std::size_t n) { node.onTf(d, n, true); });
}

void announce(const Ros2Config& c) {
    for (const std::string& note : c.notes) std::fprintf(stderr, "[kfd_ros2] %s\n", note.c_str());
    const char* odom = c.odometry == Ros2Config::Odometry::Tf      ? "tf"
                       : c.odometry == Ros2Config::Odometry::Topic ? "the odom topic"
                                                                   : "none (laser only)";
    std::fprintf(stderr,
                 "[kfd_ros2] filtering %s -> %s on DDS domain %d%s; odometry: %s; Ctrl-C stops\n",
                 c.ddsTopic("scan").c_str() + 2, c.ddsTopic("scan_filtered").c_str() + 2,
                 c.domain_id, c.localhost_only ? " (127.0.0.1 only)" : "", odom);
}

// Until Ctrl-C: what the node filtered goes out, the scans whose odometry wait is over are
// filtered, and the diagnostics every period.
void spin(Ros2Node& node, Outbox& box, DdsBus& bus, const Ros2Config& c) {
    double next_stats = steadySeconds() + c.stats_period;
    while (!g_stop) {
        box.flush(bus, 2);
        node.tick();
        if (steadySeconds() >= next_stats) {
            node.publishDiagnostics(wallSeconds());
            next_stats += c.stats_period;
        }
    }
}

int run(const Ros2Config& c) {
    DdsBus bus(DdsBus::Params{c.domain_id, c.localhost_only, c.node_name});
    const Writers w = advertise(bus, c);
    Outbox box;
    Ros2Node node(c, outputs(box, w), steadySeconds);
    subscribe(bus, node, c);
    announce(c);
    spin(node, box, bus, c);
    node.finish();  // a held keyframe and the scans still waiting for odometry go out
    node.publishDiagnostics(wallSeconds());
    box.flush(bus, 0);
    bus.waitForAcknowledgments(w.scan, 1.0);
    const auto k = node.counters();
    const Ros2Counters own = node.ownCounters();
    std::fprintf(stderr,
                 "[kfd_ros2] stopped: %zu of %zu scans kept, %zu bad messages, %zu odometry "
                 "timeouts, %zu filtered early (queue full); kfd's work per scan p50 %.0f us, "
                 "p99 %.0f us; %zu samples DDS refused\n",
                 k.scans_kept, k.scans_in, own.bad_messages, own.odom_timeouts, own.queue_full,
                 node.workPercentile(50.0), node.workPercentile(99.0), box.failed());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Ros2Args args;
    try {
        args = parseRos2Args(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd_ros2: %s\n(kfd_ros2 --help lists the parameters)\n", e.what());
        return 2;
    }
    if (args.help || args.version) {
        if (args.help)
            std::fputs(kUsage, stdout);
        else
            std::printf("kfd_ros2 (kfd %s)\n", KFD_VERSION);
        return 0;
    }
    std::signal(SIGINT, onStop);
    std::signal(SIGTERM, onStop);
    try {
        return run(args.config);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd_ros2: %s\n", e.what());
        return 1;
    }
}
