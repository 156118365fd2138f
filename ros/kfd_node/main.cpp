// kfd_node: kfd on a live robot (ROS 1). A thin main over kfd::ros1::ScanFilterNode
// (docs/USAGE.md, "kfd_node (ROS 1)").
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>

#include "kfd/ros1/scan_filter_node.h"

namespace {

constexpr const char* kUsage =
    "usage: kfd_node [__name:=NAME] [scan:=TOPIC] [scan_filtered:=TOPIC] [odom:=TOPIC]\n"
    "                [_PARAM:=VALUE ...]\n"
    "kfd on a live robot: sensor_msgs/LaserScan on `scan` through kfd's filter, keyframes out\n"
    "on `scan_filtered`, diagnostics on /diagnostics and ~stats.\n"
    "Parameters: ~config (a kfd .ini/.yaml), ~odom (tf | topic | none), ~odom_frame,\n"
    "~base_frame, ~tf_wait (s), ~removed_as (nan | inf), ~reset_jump (s), ~queue_size,\n"
    "~track_topic, ~track_tf, and any kfd key as ~<stage>/<key> (e.g. ~distance/max_range).\n"
    "SIGINT, SIGTERM or rosnode kill publish a keyframe held for its next scan first.\n"
    "See docs/USAGE.md, \"kfd_node (ROS 1)\"; roslaunch kfd_ros kfd.launch runs it.\n";

bool asksForHelp(int argc, char** argv) {
    for (int i = 1; i < argc; ++i)
        if (!std::strcmp(argv[i], "-h") || !std::strcmp(argv[i], "--help")) return true;
    return false;
}

}  // namespace

int main(int argc, char** argv) {
    if (asksForHelp(argc, argv)) {  // before ros::init: no master needed
        std::fputs(kUsage, stdout);
        return 0;
    }
    // SIGINT, SIGTERM and rosnode kill stop the node through kfd::ros1::GracefulStop (which
    // the node registers with): what it holds is published before ROS stops.
    ros::init(argc, argv, "kfd_node", ros::init_options::NoSigintHandler);
    ros::NodeHandle nh, pnh("~");
    std::unique_ptr<kfd::ros1::ScanFilterNode> node;
    try {
        node = std::make_unique<kfd::ros1::ScanFilterNode>(nh, pnh);
    } catch (const std::exception& e) {
        ROS_FATAL("kfd_node: %s", e.what());
        return 2;
    }
    ROS_INFO("kfd_node: filtering %s -> %s", nh.resolveName("scan").c_str(),
             nh.resolveName("scan_filtered").c_str());
    while (ros::ok()) ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
    node.reset();
    ros::shutdown();
    return 0;
}
