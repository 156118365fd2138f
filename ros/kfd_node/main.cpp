// kfd_node: kfd on a live robot (ROS 1). A thin main over kfd::ros1::ScanFilterNode
// (docs/USAGE.md, "kfd_node (ROS 1)").
#include <ros/callback_queue.h>
#include <ros/ros.h>

#include <csignal>
#include <exception>
#include <memory>

#include "kfd/ros1/scan_filter_node.h"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void onStop(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
    // Ctrl-C (or roslaunch's SIGINT) stops the spin but leaves ROS up, so that a keyframe held
    // for its next scan (~next_scan) is still published before the node goes.
    ros::init(argc, argv, "kfd_node", ros::init_options::NoSigintHandler);
    std::signal(SIGINT, onStop);
    std::signal(SIGTERM, onStop);
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
    while (ros::ok() && !g_stop)
        ros::getGlobalCallbackQueue()->callAvailable(ros::WallDuration(0.1));
    if (ros::ok() && node->finish() > 0)
        ros::WallDuration(0.5).sleep();  // the last scan reaches the subscribers
    node.reset();                        // ~stats once more
    ros::shutdown();
    return 0;
}
