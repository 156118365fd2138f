// The bag layer's NativeMessage (kfd/mrpt/source.h): one message of an open bag. Private to
// libkfd: only the bag source and the bag writer include ROS headers.
#pragma once

#include <rosbag/message_instance.h>

#include "kfd/mrpt/source.h"

namespace kfd {

struct NativeMessage {
    explicit NativeMessage(const rosbag::MessageInstance& m) : message(m) {}
    /// Valid while the BagSource that read it is alive (it refers to the open bag).
    rosbag::MessageInstance message;
};

}  // namespace kfd
