// kfd/FilterNodelet: kfd::ros1::ScanFilterNode in a nodelet manager (zero-copy from a laser
// driver nodelet). Same topics and parameters as kfd_node (docs/USAGE.md, "kfd_node (ROS 1)").
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

#include "kfd/ros1/scan_filter_node.h"

namespace kfd::ros1 {

class FilterNodelet : public nodelet::Nodelet {
  private:
    void onInit() override {
        try {
            node_ = std::make_unique<ScanFilterNode>(getNodeHandle(), getPrivateNodeHandle());
        } catch (const std::exception& e) {
            NODELET_FATAL("kfd/FilterNodelet: %s", e.what());
            throw;
        }
    }
    std::unique_ptr<ScanFilterNode> node_;
};

}  // namespace kfd::ros1

PLUGINLIB_EXPORT_CLASS(kfd::ros1::FilterNodelet, nodelet::Nodelet)
