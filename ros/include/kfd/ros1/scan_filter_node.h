// kfd on a live robot (ROS 1): LaserScans on `scan` through kfd's one door, keyframes out on
// `scan_filtered`, diagnostics on /diagnostics and ~stats. kfd_node's main and the
// kfd/FilterNodelet nodelet both wrap this class (docs/USAGE.md, "kfd_node (ROS 1)").
#pragma once

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <ros/callback_queue.h>
#include <ros/spinner.h>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "kfd/live/latency_stats.h"
#include "kfd/live/live_filter.h"
#include "kfd/live/odometry_buffer.h"
#include "kfd/ros1/node_config.h"

namespace kfd::ros1 {

// The live front end both transports share (libkfd/include/kfd/live).
using live::frameLabel;
using live::LatencyStats;
using live::LiveCounters;
using live::LiveFilter;
using live::LiveResult;
using live::OdometryBuffer;

class ScanFilterNode {
  public:
    /// Reads the private parameters of `pnh` (nodeConfig: kfd::ConfigError naming the key when
    /// one is unknown or bad; the wrappers refuse to start), then subscribes and advertises on
    /// `nh` (`scan`, `odom`, `scan_filtered`, ~track_topic, /diagnostics) and `pnh` (~stats).
    ScanFilterNode(ros::NodeHandle nh, ros::NodeHandle pnh);
    ScanFilterNode(ros::NodeHandle nh, ros::NodeHandle pnh, const NodeConfig& config);
    /// finish(), and publishes ~stats once more (nodelet unload: 0.3 s for them to go out).
    ~ScanFilterNode();

    /// One scan (the `scan` subscriber's callback; tests call it directly).
    void onScan(const sensor_msgs::LaserScan::ConstPtr& m);
    /// One odometry message (`odom`, with ~odom: topic; served on a thread of its own, so that
    /// onScan can wait for the sample after a scan).
    void onOdometry(const nav_msgs::Odometry::ConstPtr& m);

    /// The ~stats message (keys in docs/USAGE.md).
    diagnostic_msgs::DiagnosticStatus stats() const;
    /// Publishes stats() on ~stats and /diagnostics.
    void publishStats();
    /// Finishes a keyframe held for its next scan (next_scan) and publishes it: the node
    /// shutting down (kfd_node's main before ROS stops; the destructor too). The scans
    /// published.
    std::size_t finish();
    /// A stop was asked for (GracefulStop: a signal, rosnode kill): scans are dropped from now
    /// on, a wait for odometry ends, the held keyframe and the last stats are published.
    void stop();

    const NodeConfig& config() const { return config_; }
    /// The transforms the node looks up (odom_frame -> base_frame, base_frame -> laser); tests
    /// set transforms in it directly.
    tf2_ros::Buffer& tfBuffer() { return *tf_; }
    LiveCounters counters() const;

    /// The private parameters of `pnh` by name (without '~'); a nested one (~a/b) under its
    /// top-level name (a map).
    static std::map<std::string, XmlRpc::XmlRpcValue> privateParams(const ros::NodeHandle& pnh);

  private:
    // The last of the filter, once (a signal's stop and a nodelet unload may race): finish(),
    // the last stats, a log line. The keyframes it published.
    std::size_t finishOnce();
    std::size_t publishReady();  // LiveFilter::takeReady's messages on scan_filtered; mutex_ held
    // The track stage's pose of the scan `r` is about, on ~track_topic (and /tf with ~track_tf).
    // onScan's work for a scan with a usable stamp (may throw: onScan catches it).
    void handleScan(const sensor_msgs::LaserScan::ConstPtr& in, const ros::Time& now,
                    const ros::Time& stamp);
    void publishTrack(const LiveResult& r, const ros::Time& stamp);
    std::optional<Pose2D> tfAtTheEdges(const ros::Time& stamp);
    bool newestTfAfter(const ros::Time& stamp) const;  // odom -> base known after stamp
    std::optional<ros::Time> newestTf() const;         // the newest odom -> base stamp
    /// How long (ROS time, s) a scan may wait for its odometry: ~tf_wait, but at most what the
    /// scan queue absorbs meanwhile, (queue_size - 1) x the median interval between scans.
    double waitBound() const;
    /// Waits (polling every 0.5 ms) until `ready`, the ROS clock passes stamp + waitBound(),
    /// twice that in wall time has passed (the clock may stop: a bag paused or ended), or a
    /// stop is asked for. Returns whether `ready` came true.
    template <class Ready>
    bool waitFor(const ros::Time& stamp, Ready ready);
    std::optional<Pose2D> odometryAt(const ros::Time& stamp);
    Pose2D mountOf(const std::string& frame_id);
    // Counts the scans a gap in the frame's header.seq says never arrived; warns once.
    void checkSequence(const sensor_msgs::LaserScan& m);
    // Logs (throttled, once for odometry) what the result says was wrong with the scan.
    void reportScan(const sensor_msgs::LaserScan& m, const ros::Time& stamp, const LiveResult& r,
                    bool has_odometry);

    NodeConfig config_;
    ros::NodeHandle nh_, pnh_;
    mutable std::mutex mutex_;  // the filter, the mounts, the latencies
    LiveFilter filter_;
    std::size_t evicted_seen_ = 0;  // sensors_evicted already warned about
    bool warned_missing_ = false;   // scans_missing / odom_missing warned about once
    bool warned_odom_ = false;
    std::map<std::string, std::uint32_t> last_seq_;  // per frame, for scans_missing
    std::atomic<bool> stopping_{false};
    std::atomic<bool> finished_{false};  // finishOnce ran
    std::size_t stop_token_ = 0;         // GracefulStop's registration
    std::mutex odom_mutex_;              // the odometry samples (their own thread: see onOdometry)
    std::condition_variable odom_cv_;
    OdometryBuffer odom_buffer_;
    LatencyStats latency_;  // callback entry to publish return
    LatencyStats work_;     // odometry in hand (or given up on) to publish return: kfd's own
    static constexpr std::size_t kIntervals = 32;  // scan intervals kept for waitBound
    std::vector<double> intervals_;                // the last kIntervals (|stamp difference|), s
    double scan_time_ = 0.0;  // the last scan's own scan_time (s), before intervals are known
    std::size_t next_interval_ = 0;  // ring position in intervals_
    std::optional<ros::Time> last_scan_stamp_;
    // /tf down: the newest transform when a scan's wait last timed out. Until a newer one comes,
    // scans do not wait (laser only at once, counted), so the queue keeps flowing.
    std::optional<ros::Time> tf_timed_out_at_;
    std::map<std::string, Pose2D> mounts_;  // per laser frame, once found in /tf(_static)
    std::unique_ptr<tf2_ros::Buffer> tf_;
    std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
    // `odom` is served by its own thread, so that a scan can wait for the sample after it (the
    // queue outlives the subscriber: declared first).
    ros::CallbackQueue odom_queue_;
    ros::Subscriber scan_sub_, odom_sub_;
    std::unique_ptr<ros::AsyncSpinner> odom_spinner_;
    ros::Publisher scan_pub_, diag_pub_, stats_pub_;
    ros::Publisher track_pub_;  // ~track_topic, when the pipeline lists the track stage
    std::unique_ptr<tf2_ros::TransformBroadcaster> track_tf_;  // ~track_tf
    ros::WallTimer timer_;
};

}  // namespace kfd::ros1
