// kfd's ROS 2 node without its transport: CDR messages in (scan, odometry, tf, tf_static), CDR
// messages out (keyframes with removed points marked, the tracked pose, diagnostics). The scans go
// through the live front end the ROS 1 node uses (kfd::live:: LiveFilter, the one door), so both
// nodes, and kfd-filter offline, decide alike. The DDS wiring is kfd_ros2's main (dds_bus.h); tests
// and the fuzz target drive this class directly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "kfd/live/latency_stats.h"
#include "kfd/live/live_filter.h"
#include "kfd/live/odometry_buffer.h"
#include "kfd/ros2/node_params.h"

namespace kfd::ros2 {

using Bytes = std::vector<std::uint8_t>;

/// Where the node's messages go (CDR with its encapsulation header); unset ones are skipped.
struct Ros2Outputs {
    std::function<void(const Bytes&)> scan_filtered;  // sensor_msgs/msg/LaserScan
    std::function<void(const Bytes&)> track;          // nav_msgs/msg/Odometry
    std::function<void(const Bytes&)> diagnostics;    // diagnostic_msgs/msg/DiagnosticArray
    /// Something the user should read (a bad message's first occurrence, odometry missing).
    std::function<void(const std::string&)> log;
};

/// The ROS 2 node's own counters, beside the live front end's.
struct Ros2Counters {
    std::size_t bad_messages = 0;   // undecodable CDR (any topic): dropped, first one logged
    std::size_t odom_timeouts = 0;  // scans that waited tf_wait for odometry in vain
    std::size_t queue_full = 0;     // scans filtered before their odometry came: queue full
};

class Ros2Node {
  public:
    /// `now` gives the wall clock (s, monotonic): the odometry wait's bound.
    Ros2Node(const Ros2Config& config, Ros2Outputs outputs, std::function<double()> now);

    /// One message of each input topic (thread-safe: DDS delivers on its own threads).
    void onScan(const std::uint8_t* data, std::size_t size);
    void onOdometry(const std::uint8_t* data, std::size_t size);
    void onTf(const std::uint8_t* data, std::size_t size, bool is_static);
    /// Filters the scans whose odometry wait is over (call every few ms).
    void tick();
    /// Filters every waiting scan with what odometry there is and finishes a held keyframe:
    /// the node stopping. Nothing received is lost.
    void finish();
    /// The diagnostics message (stamped `stamp_s`), also sent to outputs.diagnostics.
    Bytes publishDiagnostics(double stamp_s);

    live::LiveCounters counters() const;
    Ros2Counters ownCounters() const;
    std::size_t waiting() const;
    /// kfd's own work per scan (decode, filter, encode, hand over), microseconds.
    double workPercentile(double p) const;

  private:
    struct Waiting {
        sensor_msgs::LaserScan m;
        double stamp = 0.0;     // s
        double received = 0.0;  // now() at arrival
    };
    void drain(bool all);  // mutex_ held
    bool odometryCame(double stamp) const;
    void filterOne(Waiting& w);
    Pose2D mountOf(const std::string& frame) const;
    void addOdometry(double stamp, const Pose2D& p);
    void bad(const std::string& what);
    /// Decodes one message; false (counted, the first one logged) when it is not one.
    template <class Message>
    bool decoded(const std::uint8_t* data, std::size_t size, Message& m);

    Ros2Config config_;
    Ros2Outputs out_;
    std::function<double()> now_;
    mutable std::mutex mutex_;
    live::LiveFilter filter_;
    live::OdometryBuffer odom_;
    std::deque<Waiting> waiting_;
    // Odometry down: the newest sample's stamp when a wait last timed out. Until a newer one
    // comes, scans do not wait (laser only at once, counted), so the queue keeps flowing.
    std::optional<double> odom_down_at_;
    struct Edge {
        std::string parent;
        Pose2D pose;
    };
    std::map<std::string, Edge> static_tf_;  // child frame -> its parent and pose (tf_static)
    live::LatencyStats work_;
    Ros2Counters own_;
    Ros2Counters reported_;  // own_ at the last diagnostics (a rise since then warns)
};

}  // namespace kfd::ros2
