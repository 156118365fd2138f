// The ROS 2 node's settings from its command line, in ROS 2's own form:
//   kfd_ros2 --ros-args -p odom:=topic -p distance.max_range:=20 -r scan:=/front/scan
//            --params-file kfd.yaml
// Its own parameters (odom, frames, QoS, domain, ...) and kfd's keys (`config` file, then
// `<stage>.<key>`, `pipeline`, `selector`, `variant`), validated as kfd-filter validates a -c file.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "kfd/io/bag_writer.h"
#include "kfd/pipeline/pipeline.h"

namespace kfd::ros2 {

/// DDS QoS reliability of one endpoint.
enum class Reliability { BestEffort, Reliable };

/// The node's configuration (docs/USAGE.md, "kfd_ros2 (ROS 2)" lists every parameter).
struct Ros2Config {
    enum class Odometry { Tf, Topic, None };
    Pipeline::Params pipeline;             // `config` then the <stage>.<key> overrides
    std::string config_path;               // config ("" = kfd's defaults)
    Odometry odometry = Odometry::Tf;      // odom: tf | topic | none
    std::string odom_frame = "odom";       // odom_frame
    std::string base_frame = "base_link";  // base_frame
    double tf_wait = 1.0;                  // tf_wait, s (wall): a scan's longest wait for odometry
    RemovedMark removed = RemovedMark::NaN;  // removed_as: nan | inf
    double reset_jump = 1.0;                 // reset_jump, s (LiveFilter::Params::reset_jump)
    int queue_size = 10;  // queue_size: scans waiting for odometry; the output writer's depth
    /// track_topic: the tracked pose of every scan (nav_msgs/Odometry) when the pipeline lists
    /// the track stage; "" publishes none.
    std::string track_topic = "tracked_odom";
    int domain_id = 0;            // domain_id (default: $ROS_DOMAIN_ID, else 0)
    bool localhost_only = false;  // localhost_only (default: $ROS_LOCALHOST_ONLY == 1)
    Reliability scan_reliability = Reliability::BestEffort;  // scan_qos: best_effort | reliable
    double stats_period = 1.0;      // stats_period, s: diagnostics every this long
    std::string node_name = "kfd";  // -r __node:=NAME (the diagnostics' name)
    std::string ns;                 // -r __ns:=/NS (prefix of relative topic names)
    /// ROS topic names after remapping (-r from:=to), keyed by the node's name for them:
    /// scan, odom, tf, tf_static, scan_filtered, diagnostics, and track_topic's name.
    std::vector<std::pair<std::string, std::string>> remaps;
    std::vector<std::string> notes;  // what the user should know (logged at start)

    /// The DDS topic of one of the node's topics: remapped, namespaced, "rt" + absolute name
    /// ("scan" -> "rt/scan"; with __ns:=/robot1, "rt/robot1/scan"; "/tf" stays "rt/tf").
    std::string ddsTopic(const std::string& name) const;
};

/// What the command line asks for.
struct Ros2Args {
    bool help = false, version = false;
    Ros2Config config;
};

/// Parses argv (argv[0] skipped): --help, --version, then ROS 2's `--ros-args` with any of
/// `-p name:=value`, `--param name:=value`, `-r from:=to`, `--remap`, `--params-file FILE`
/// (a ROS 2 parameters YAML: `<node or /**>: ros__parameters: {...}`, nested maps as
/// <stage>.<key>), `--log-level L` (accepted), ended by `--` or the end. Environment:
/// ROS_DOMAIN_ID and ROS_LOCALHOST_ONLY give the defaults. kfd::ConfigError naming the
/// parameter on anything unknown or bad.
Ros2Args parseRos2Args(int argc, const char* const* argv);

/// The settings from (name, value text) pairs as -p gives them, over the environment's
/// defaults; what parseRos2Args does after reading the command line.
Ros2Config ros2Config(const std::vector<std::pair<std::string, std::string>>& params,
                      const std::vector<std::pair<std::string, std::string>>& remaps);

}  // namespace kfd::ros2
