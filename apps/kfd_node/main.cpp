// kfd_node: kfd on a live robot (ROS 1). A thin main over kfd::ros1::ScanFilterNode
// (docs/USAGE.md, "kfd_node (ROS 1)").
#include <ros/ros.h>

#include <exception>
#include <memory>

#include "kfd/ros1/scan_filter_node.h"

int main(int argc, char** argv) {
    ros::init(argc, argv, "kfd_node");
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
    ros::spin();
    return 0;
}
