// The bag layer's NativeMessage (kfd/io/source.h): one message of an open bag. Private to
// libkfd: only the bag source and the bag writer include ROS headers.
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/serialization.h>
#include <rosbag/structures.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>
#include <boost/make_shared.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "kfd/io/laser_scan.h"
#include "kfd/io/ros2_message.h"
#include "kfd/io/source.h"

namespace kfd {

/// A topic of a ROS 2 log (rosbag2 or MCAP): what its messages need to be read and copied.
struct Ros2Connection {
    std::string topic;
    std::string type;                             // "sensor_msgs/msg/LaserScan"
    std::string encoding = "cdr";                 // serialization_format / MCAP message_encoding
    std::string offered_qos_profiles;             // rosbag2's YAML (MCAP: the channel's metadata)
    std::string type_description_hash;            // Jazzy's RIHS01_..., when the file has it
    std::string schema_encoding;                  // MCAP: "ros2msg", "ros1msg", ... ("" : none)
    std::string schema_data;                      // MCAP: the schema's definition
    std::map<std::string, std::string> metadata;  // MCAP channel metadata
};

/// One message of a bag: its connection (topic, type, MD5 sum, definition, connection header),
/// bag time and serialized bytes, copied out of its chunk (BagReader): writing or
/// deserializing it reads nothing from the bag again. A message of a ROS 2 log (rosbag2, MCAP)
/// has `ros2` instead of `connection`, and its log time in nanoseconds.
struct NativeMessage {
    /// Valid while the BagSource that read it is alive (it belongs to the open bag).
    const rosbag::ConnectionInfo* connection = nullptr;
    const Ros2Connection* ros2 = nullptr;
    ros::Time time;
    std::int64_t time_ns = 0;  // ROS 2: the receive (log) time; ROS 1: 0
    std::vector<std::uint8_t> bytes;

    const std::string& topic() const { return ros2 ? ros2->topic : connection->topic; }
    /// True when the message is a T (ROS 1: by MD5 sum, as rosbag::MessageInstance::isType;
    /// ROS 2: by type name, in CDR or in ROS 1's encoding, as MCAP's ros1 profile holds).
    template <class T>
    bool isType() const {
        if (ros2)
            return (ros2->encoding == "cdr" || ros2->encoding == "ros1") &&
                   ros1TypeName(ros2->type) == ros::message_traits::DataType<T>::value();
        const char* md5 = ros::message_traits::MD5Sum<T>::value();
        return std::strcmp(md5, "*") == 0 || connection->md5sum == md5;
    }
    /// The message deserialized as a T (as rosbag::MessageInstance::instantiate, without
    /// checking its bytes: see instantiateChecked), or null when it is not a T. A CDR message
    /// is always checked (decodeRos2).
    template <class T>
    boost::shared_ptr<T> instantiate() const {
        if (!isType<T>()) return nullptr;
        auto p = boost::make_shared<T>();
        if (ros2 && ros2->encoding == "cdr") {
            decodeRos2(bytes.data(), bytes.size(), *p);
            return p;
        }
        ros::serialization::PreDeserializeParams<T> params;
        params.message = p;
        if (connection) params.connection_header = connection->header;
        ros::serialization::PreDeserialize<T>::notify(params);
        ros::serialization::IStream s(const_cast<std::uint8_t*>(bytes.data()),
                                      static_cast<std::uint32_t>(bytes.size()));
        ros::serialization::deserialize(s, *p);
        return p;
    }
};

/// The message types kfd deserializes, by their serialized layout.
enum class MessageLayout { LaserScan, Odometry, TfMessage };

/// Checks serialized message bytes against `layout` before anything is allocated for them:
/// every string and array length must fit in the bytes left of the message (for an array of
/// TransformStamped, its count times the least one element takes). Throws BagError
/// ("corrupt sensor_msgs/LaserScan: ranges: array length 1073741824 (4294967296 bytes) does
/// not fit in the message's 781 bytes (728 left)"), without the file or the message: the
/// caller names them. Bytes after the last field are allowed, as roscpp does.
void checkMessageBytes(MessageLayout layout, const unsigned char* data, std::size_t size);
/// The same on a bag message's bytes.
inline void checkMessageBytes(MessageLayout layout, const NativeMessage& m) {
    checkMessageBytes(layout, m.bytes.data(), m.bytes.size());
}

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
boost::shared_ptr<T> instantiateChecked(const NativeMessage& m) {
    if (!m.isType<T>()) return nullptr;
    if (!m.ros2 || m.ros2->encoding != "cdr")  // CDR is checked as it is decoded
        checkMessageBytes(LayoutOf<T>::value, m);
    return m.instantiate<T>();
}

}  // namespace kfd

// A NativeMessage written to a bag as it was read: its bytes under its connection's type, MD5
// sum and definition (rosbag::Bag::write).
namespace ros {
namespace message_traits {
template <>
struct IsMessage<kfd::NativeMessage> : TrueType {};
template <>
struct MD5Sum<kfd::NativeMessage> {
    static const char* value(const kfd::NativeMessage& m) { return m.connection->md5sum.c_str(); }
};
template <>
struct DataType<kfd::NativeMessage> {
    static const char* value(const kfd::NativeMessage& m) { return m.connection->datatype.c_str(); }
};
template <>
struct Definition<kfd::NativeMessage> {
    static const char* value(const kfd::NativeMessage& m) { return m.connection->msg_def.c_str(); }
};
}  // namespace message_traits
namespace serialization {
template <>
struct Serializer<kfd::NativeMessage> {
    template <class Stream>
    static void write(Stream& stream, const kfd::NativeMessage& m) {
        if (!m.bytes.empty())
            std::memcpy(stream.advance(static_cast<std::uint32_t>(m.bytes.size())), m.bytes.data(),
                        m.bytes.size());
    }
    static std::uint32_t serializedLength(const kfd::NativeMessage& m) {
        return static_cast<std::uint32_t>(m.bytes.size());
    }
};
}  // namespace serialization
}  // namespace ros
