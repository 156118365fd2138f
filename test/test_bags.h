// Tiny hand-made ROS 1 bags for the tests (written with Debian's rosbag_storage).
#pragma once

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace kfd {
namespace test {

/// A message's serialized bytes, written to a bag as they are under T's type name and MD5 sum:
/// how the tests put a corrupt LaserScan, Odometry or TFMessage into a bag of any compression.
template <class T>
struct Serialized {
    std::vector<std::uint8_t> bytes;
};

/// `msg` serialized (ROS 1: little-endian, uint32 lengths before strings and arrays).
template <class T>
Serialized<T> serialized(const T& msg) {
    Serialized<T> s;
    s.bytes.resize(ros::serialization::serializationLength(msg));
    ros::serialization::OStream out(s.bytes.data(), static_cast<std::uint32_t>(s.bytes.size()));
    ros::serialization::serialize(out, msg);
    return s;
}

/// Overwrites the uint32 at byte `at` (a length field, to corrupt it).
template <class T>
Serialized<T> withU32(Serialized<T> s, std::size_t at, std::uint32_t value) {
    for (int i = 0; i < 4; ++i) s.bytes.at(at + i) = static_cast<std::uint8_t>(value >> (8 * i));
    return s;
}

/// Byte offsets of a LaserScan's length fields (frame_id's length sets where the others are).
inline std::size_t frameIdLengthAt() { return 12; }
inline std::size_t rangesLengthAt(const sensor_msgs::LaserScan& m) {
    return 12 + 4 + m.header.frame_id.size() + 7 * 4;
}
inline std::size_t intensitiesLengthAt(const sensor_msgs::LaserScan& m) {
    return rangesLengthAt(m) + 4 + 4 * m.ranges.size();
}

inline geometry_msgs::Quaternion yawQuaternion(double yaw) {
    geometry_msgs::Quaternion q;
    q.z = std::sin(yaw / 2);
    q.w = std::cos(yaw / 2);
    return q;
}

/// Writes a bag message by message (bag time = header stamp unless given).
class BagBuilder {
  public:
    explicit BagBuilder(const std::string& path, rosbag::compression::CompressionType c =
                                                     rosbag::compression::Uncompressed) {
        bag_.open(path, rosbag::bagmode::Write);
        bag_.setCompression(c);
    }
    ~BagBuilder() { close(); }
    void close() {
        if (open_) bag_.close();
        open_ = false;
    }

    static sensor_msgs::LaserScan scanMsg(double t, const std::vector<float>& ranges,
                                          const std::string& frame = "laser",
                                          float angle_min = -1.5f, float angle_max = 1.5f,
                                          float range_min = 0.1f, float range_max = 10.0f) {
        sensor_msgs::LaserScan m;
        m.header.stamp = ros::Time(t);
        m.header.frame_id = frame;
        m.angle_min = angle_min;
        m.angle_max = angle_max;
        m.angle_increment = ranges.size() > 1
                                ? (angle_max - angle_min) / static_cast<float>(ranges.size() - 1)
                                : 0.f;
        m.range_min = range_min;
        m.range_max = range_max;
        m.ranges = ranges;
        return m;
    }
    void scan(const std::string& topic, const sensor_msgs::LaserScan& m, double bag_time = -1) {
        bag_.write(topic, ros::Time(bag_time >= 0 ? bag_time : m.header.stamp.toSec()), m);
    }
    /// A message given as its bytes (see Serialized), at bag time `t`.
    template <class T>
    void raw(const std::string& topic, double t, const Serialized<T>& m) {
        bag_.write(topic, ros::Time(t), m);
    }
    void odom(const std::string& topic, double t, double x, double y, double yaw,
              const std::string& child = "base_link") {
        nav_msgs::Odometry m;
        m.header.stamp = ros::Time(t);
        m.header.frame_id = "odom";
        m.child_frame_id = child;
        m.pose.pose.position.x = x;
        m.pose.pose.position.y = y;
        m.pose.pose.orientation = yawQuaternion(yaw);
        bag_.write(topic, ros::Time(t), m);
    }
    void tf(const std::string& topic, double t, const std::string& parent, const std::string& child,
            double x, double y, double yaw) {
        tf2_msgs::TFMessage m;
        geometry_msgs::TransformStamped ts;
        ts.header.stamp = ros::Time(t);
        ts.header.frame_id = parent;
        ts.child_frame_id = child;
        ts.transform.translation.x = x;
        ts.transform.translation.y = y;
        ts.transform.rotation = yawQuaternion(yaw);
        m.transforms.push_back(ts);
        bag_.write(topic, ros::Time(t), m);
    }

  private:
    rosbag::Bag bag_;
    bool open_ = true;
};

}  // namespace test
}  // namespace kfd

namespace ros {
namespace message_traits {
template <class T>
struct IsMessage<kfd::test::Serialized<T>> : TrueType {};
template <class T>
struct MD5Sum<kfd::test::Serialized<T>> {
    static const char* value() { return MD5Sum<T>::value(); }
    static const char* value(const kfd::test::Serialized<T>&) { return value(); }
};
template <class T>
struct DataType<kfd::test::Serialized<T>> {
    static const char* value() { return DataType<T>::value(); }
    static const char* value(const kfd::test::Serialized<T>&) { return value(); }
};
template <class T>
struct Definition<kfd::test::Serialized<T>> {
    static const char* value() { return Definition<T>::value(); }
    static const char* value(const kfd::test::Serialized<T>&) { return value(); }
};
}  // namespace message_traits
namespace serialization {
template <class T>
struct Serializer<kfd::test::Serialized<T>> {
    template <class Stream>
    static void write(Stream& stream, const kfd::test::Serialized<T>& m) {
        std::memcpy(stream.advance(static_cast<std::uint32_t>(m.bytes.size())), m.bytes.data(),
                    m.bytes.size());
    }
    static std::uint32_t serializedLength(const kfd::test::Serialized<T>& m) {
        return static_cast<std::uint32_t>(m.bytes.size());
    }
};
}  // namespace serialization
}  // namespace ros
