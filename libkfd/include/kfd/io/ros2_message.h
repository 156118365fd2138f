// ROS 2 messages in CDR (rosbag2 and MCAP files) read into, and written from, the ROS 1 message
// structs that the rest of the bag layer uses: a LaserScan is the same message in both (ROS 2's
// Header has no `seq`; its stamp is int32 sec + uint32 nanosec). The bag layer and the ROS 2
// node (ros2/) use them.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace kfd {

/// The ROS 1 form of a ROS 2 type name ("sensor_msgs/msg/LaserScan" -> "sensor_msgs/LaserScan"):
/// how the bag layer compares types across both. Other names come back unchanged.
std::string ros1TypeName(const std::string& type);

/// Decodes CDR `data` (encapsulation header included) as the ROS 2 form of the message; a
/// header stamp with a negative second or nanoseconds of 10^9 or more is refused. Throws BagError
/// "corrupt sensor_msgs/msg/LaserScan: ranges: ..." (the caller names the file and message).
void decodeRos2(const std::uint8_t* data, std::size_t size, sensor_msgs::LaserScan& out);
void decodeRos2(const std::uint8_t* data, std::size_t size, nav_msgs::Odometry& out);
void decodeRos2(const std::uint8_t* data, std::size_t size, tf2_msgs::TFMessage& out);
void decodeRos2(const std::uint8_t* data, std::size_t size, diagnostic_msgs::DiagnosticArray& out);

/// The CDR of `m` as a ROS 2 sensor_msgs/msg/LaserScan (little-endian on this machine, header
/// included); `seq` is left out.
std::vector<std::uint8_t> encodeRos2(const sensor_msgs::LaserScan& m);
std::vector<std::uint8_t> encodeRos2(const nav_msgs::Odometry& m);
std::vector<std::uint8_t> encodeRos2(const tf2_msgs::TFMessage& m);
std::vector<std::uint8_t> encodeRos2(const diagnostic_msgs::DiagnosticArray& m);

/// The ros2msg definition of a type kfd writes (MCAP's ros2 profile: the message's .msg text,
/// then each nested type after a line of '=' and "MSG: pkg/msg/Name"); empty for others.
const std::string& ros2Definition(const std::string& ros2_type);

}  // namespace kfd
