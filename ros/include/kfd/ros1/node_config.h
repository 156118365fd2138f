// The node's parameters: its own (~odom, ~removed_as, ...) and kfd's keys (~config and ~KEY
// overrides), validated as kfd-filter validates a -c file.
#pragma once

#include <xmlrpcpp/XmlRpcValue.h>

#include <map>
#include <string>
#include <vector>

#include "kfd/io/bag_writer.h"
#include "kfd/pipeline/pipeline.h"

namespace kfd::ros1 {

/// The node's own settings (every private parameter that is not a kfd key).
struct NodeConfig {
    enum class Odometry { Tf, Topic, None };
    Pipeline::Params pipeline;             // ~config then the ~KEY overrides, validated
    std::string config_path;               // ~config ("" = kfd's defaults, share/kfd/default.ini)
    Odometry odometry = Odometry::Tf;      // ~odom: tf | topic | none
    std::string odom_frame = "odom";       // ~odom_frame
    std::string base_frame = "base_link";  // ~base_frame
    // ~tf_wait, s of ROS time after the scan's stamp: the longest a scan waits for its odometry
    // (odom_frame -> base_frame, or the odometry sample after it); 1 s, the bag source's hold.
    // The node also never waits longer than its queue can absorb (ScanFilterNode::waitBound).
    double tf_wait = 1.0;
    RemovedMark removed = RemovedMark::NaN;  // ~removed_as: nan | inf
    double reset_jump = 1.0;                 // ~reset_jump, s (LiveFilter::Params::reset_jump)
    int queue_size = 10;  // ~queue_size: the scan subscriber's and publisher's queues
    /// ~max_sensors: frame ids whose state is kept at most; a new one beyond it evicts the one
    /// heard from longest ago (sensors_evicted; memory stays bounded under a flood of ids).
    int max_sensors = 64;
    /// ~track_topic: where the tracked pose of every scan goes (nav_msgs/Odometry, frame
    /// odom_frame, child base_frame) when the pipeline lists the track stage; "" publishes none.
    std::string track_topic = "tracked_odom";
    /// ~track_tf: also broadcast the tracked pose as the transform odom_frame -> base_frame
    /// (a robot without wheel odometry); refused with ~odom: tf, which reads that transform.
    bool track_tf = false;
    /// What the user should know (flat kfd keys read for this release, with their new
    /// spelling ~<stage>/<key>): the node logs them at start.
    std::vector<std::string> notes;
};

/// The node's own parameter names (without '~').
bool isNodeParameter(const std::string& name);

/// The node's configuration from its private parameters (names without '~', values as the
/// parameter server holds them). kfd's configuration: ~config's file (kfd::loadConfigFile) or
/// kfd's defaults, then every other parameter as a kfd key: a stage's map `~<stage>/<key>`
/// (e.g. ~distance/max_range; kfd::applyConfig), or `~pipeline`, `~selector`, `~variant`, or
/// a flat key of before (read for this release, with a note): ints, doubles, bools and
/// strings as their text, a list as its comma-separated items; then kfd::validateConfig.
/// kfd::ConfigError naming the parameter (e.g. "config key 'window': ...", "config key 'odom':
/// ...") on an unknown key, a bad value or a value of the wrong type: the node refuses to start.
NodeConfig nodeConfig(const std::map<std::string, XmlRpc::XmlRpcValue>& params);

}  // namespace kfd::ros1
