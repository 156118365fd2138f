// The bag layer's NativeMessage (kfd/mrpt/source.h): one message of an open bag. Private to
// libkfd: only the bag source and the bag writer include ROS headers.
#pragma once

#include <nav_msgs/Odometry.h>
#include <rosbag/message_instance.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstddef>

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

/// The message types kfd deserializes, by their serialized layout.
enum class MessageLayout { LaserScan, Odometry, TfMessage };

/// Checks serialized message bytes against `layout` before anything is allocated for them:
/// every string and array length must fit in the bytes left of the message (for an array of
/// TransformStamped, its count times the least one element takes). Throws BagError
/// ("corrupt sensor_msgs/LaserScan: ranges: array length 1073741824 (4294967296 bytes) does
/// not fit in the message's 781 bytes (728 left)"), without the file or the message: the
/// caller names them. Bytes after the last field are allowed, as roscpp does.
void checkMessageBytes(MessageLayout layout, const unsigned char* data, std::size_t size);
/// The same on a bag message's bytes (copied out of rosbag's chunk buffer).
void checkMessageBytes(MessageLayout layout, const rosbag::MessageInstance& m);

template <class T>
struct LayoutOf;
template <>
struct LayoutOf<sensor_msgs::LaserScan> {
    static constexpr MessageLayout value = MessageLayout::LaserScan;
};
template <>
struct LayoutOf<nav_msgs::Odometry> {
    static constexpr MessageLayout value = MessageLayout::Odometry;
};
template <>
struct LayoutOf<tf2_msgs::TFMessage> {
    static constexpr MessageLayout value = MessageLayout::TfMessage;
};

/// `m` as a T, or null when it is not one (MessageInstance::instantiate), its bytes checked
/// first (checkMessageBytes): kfd instantiates no bag message otherwise. BagError for corrupt
/// bytes, without the file or the message (the caller names them).
template <class T>
boost::shared_ptr<T> instantiateChecked(const rosbag::MessageInstance& m) {
    if (!m.isType<T>()) return nullptr;
    checkMessageBytes(LayoutOf<T>::value, m);
    return m.instantiate<T>();
}

}  // namespace kfd
