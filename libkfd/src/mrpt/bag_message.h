// The bag layer's NativeMessage (kfd/mrpt/source.h): one message of an open bag. Private to
// libkfd: only the bag source and the bag writer include ROS headers.
#pragma once

#include <rosbag/message_instance.h>
#include <sensor_msgs/LaserScan.h>

#include <cmath>

#include "kfd/mrpt/source.h"

namespace kfd {

struct NativeMessage {
    explicit NativeMessage(const rosbag::MessageInstance& m) : message(m) {}
    /// Valid while the BagSource that read it is alive (it refers to the open bag).
    rosbag::MessageInstance message;
};

/// The one beam validity rule of a LaserScan (the source's and the writer's): finite and
/// range_min <= r < range_max (r = range_max is "no return", as in MRPT's rawlogs and CARMEN).
inline bool validRange(const sensor_msgs::LaserScan& m, float r) {
    return std::isfinite(r) && r >= m.range_min && r < m.range_max;
}

}  // namespace kfd
