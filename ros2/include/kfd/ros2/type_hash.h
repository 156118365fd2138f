// The ROS 2 type hash (REP 2011, "RIHS01_<sha256>") of the messages kfd's ROS 2 node speaks: Jazzy
// puts `typehash=<hash>;` in a participant's endpoint USER_DATA and warns when a peer's is
// missing. Computed from the types' descriptions as rosidl does (a JSON of the type and its
// referenced types, sorted by name, without default values), not copied.
#pragma once

#include <string>

namespace kfd::ros2 {

/// "RIHS01_" + 64 hex digits for a ROS 2 type kfd knows ("sensor_msgs/msg/LaserScan",
/// "nav_msgs/msg/Odometry", "tf2_msgs/msg/TFMessage", "diagnostic_msgs/msg/DiagnosticArray",
/// and the types they hold); std::invalid_argument for another.
std::string typeHash(const std::string& ros2_type);

/// The description rosidl hashes for that type (the JSON text; tests and docs).
std::string typeDescriptionJson(const std::string& ros2_type);

/// DDS type name of a ROS 2 type: "sensor_msgs/msg/LaserScan" ->
/// "sensor_msgs::msg::dds_::LaserScan_".
std::string ddsTypeName(const std::string& ros2_type);

}  // namespace kfd::ros2
