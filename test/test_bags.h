// Tiny hand-made ROS 1 bags for the tests (written with Debian's rosbag_storage).
#pragma once

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/MultiEchoLaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <utility>
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

/// The ranges a robot at (x, y, yaw) sees in a 6 m x 4 m room centred on the origin, beams over
/// [-fov/2, fov/2].
inline std::vector<float> room(double x, double y, double yaw, std::size_t n, double fov = 3.0) {
    std::vector<float> r(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double a = yaw - fov / 2 + fov * static_cast<double>(i) / static_cast<double>(n - 1);
        const double c = std::cos(a), s = std::sin(a);
        double d = 1e9;
        if (c > 1e-9) d = std::min(d, (3.0 - x) / c);
        if (c < -1e-9) d = std::min(d, (-3.0 - x) / c);
        if (s > 1e-9) d = std::min(d, (2.0 - y) / s);
        if (s < -1e-9) d = std::min(d, (-2.0 - y) / s);
        r[i] = static_cast<float>(d);
    }
    return r;
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
    /// One transform parent -> child stamped t.
    static tf2_msgs::TFMessage tfMsg(double t, const std::string& parent, const std::string& child,
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
        return m;
    }
    void tf(const std::string& topic, double t, const std::string& parent, const std::string& child,
            double x, double y, double yaw) {
        bag_.write(topic, ros::Time(t), tfMsg(t, parent, child, x, y, yaw));
    }

  private:
    rosbag::Bag bag_;
    bool open_ = true;
};

/// The scanner of writeFastScannerBag: its rate, beam count and field of view.
struct FastScanner {
    double scan_hz = 35;       // /scan and /echoes rate (Hz)
    std::size_t beams = 1079;  // beams per scan
    double fov = 3.0;          // field of view (rad), centred on the robot's heading
    double noise = 0;          // range noise (m): uniform in [-noise, noise], the same every run
};

/// A bag like a fast scanner's (issue 23's measurements; its tests): /scan at 35 Hz (1079 beams;
/// `scanner` changes them) beside multi-echo scans, an IMU at 200 Hz, odometry and /tf at 50 Hz,
/// over `seconds`; several chunks. Stamps are distinct across topics. `by_topic`: written one
/// topic after the other (the chunks' times overlap: reading in time order goes back and forth
/// between them), else in time order.
inline void writeFastScannerBag(const std::string& path, rosbag::compression::CompressionType c,
                                bool by_topic, double seconds, const FastScanner& scanner = {}) {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    bag.setCompression(c);
    struct Stamped {
        double t;
        int topic;
    };
    std::vector<Stamped> all;
    auto every = [&](int topic, double hz, double phase) {
        for (double t = 1.0 + phase; t < 1.0 + seconds; t += 1.0 / hz) all.push_back({t, topic});
    };
    every(0, scanner.scan_hz, 0.0003);  // /scan
    every(1, scanner.scan_hz, 0.0007);  // /echoes
    every(2, 200, 0.0011);              // /imu
    every(3, 50, 0.0013);               // /odom and /tf
    if (by_topic)
        std::stable_sort(all.begin(), all.end(),
                         [](const Stamped& a, const Stamped& b) { return a.topic < b.topic; });
    else
        std::stable_sort(all.begin(), all.end(),
                         [](const Stamped& a, const Stamped& b) { return a.t < b.t; });
    auto tfs = [](double t, const std::string& parent, const std::string& child, double x) {
        return BagBuilder::tfMsg(t, parent, child, x, 0, 0);
    };
    const auto n = scanner.beams;
    const auto half = static_cast<float>(scanner.fov / 2);
    std::uint32_t lcg = 12345;
    auto noisy = [&](std::vector<float> r) {
        if (scanner.noise > 0)
            for (auto& v : r) {
                lcg = lcg * 1664525u + 1013904223u;
                v += static_cast<float>(scanner.noise * (2.0 * (lcg >> 8) / 16777216.0 - 1.0));
            }
        return r;
    };
    bag.write("/tf_static", ros::Time(1.0), tfs(1.0, "base_link", "laser", 0.1));
    for (const auto& s : all) {
        const double x = 0.3 * (s.t - 1.0);  // 0.3 m/s along x
        if (s.topic == 0) {
            bag.write("/scan", ros::Time(s.t),
                      BagBuilder::scanMsg(s.t, noisy(room(x + 0.1, 0, 0, n, scanner.fov)), "laser",
                                          -half, half));
        } else if (s.topic == 1) {
            sensor_msgs::MultiEchoLaserScan m;
            m.header.stamp = ros::Time(s.t);
            m.header.frame_id = "laser";
            m.ranges.resize(n);
            const auto r = room(x + 0.1, 0, 0, n, scanner.fov);
            for (std::size_t i = 0; i < r.size(); ++i)
                m.ranges[i].echoes = {r[i], r[i] + 0.01f * static_cast<float>(i % 7), 0.0f};
            bag.write("/echoes", ros::Time(s.t), m);
        } else if (s.topic == 2) {
            sensor_msgs::Imu m;
            m.header.stamp = ros::Time(s.t);
            m.header.frame_id = "imu";
            m.linear_acceleration.x = 0.01 * std::sin(100 * s.t);
            m.orientation.w = 1;
            bag.write("/imu", ros::Time(s.t), m);
        } else {
            nav_msgs::Odometry m;
            m.header.stamp = ros::Time(s.t);
            m.header.frame_id = "odom";
            m.child_frame_id = "base_link";
            m.pose.pose.position.x = x;
            m.pose.pose.orientation.w = 1;
            bag.write("/odom", ros::Time(s.t), m);
            bag.write("/tf", ros::Time(s.t + 0.0001), tfs(s.t, "odom", "base_link", x));
        }
    }
    bag.close();
}

/// The chunk compressions of rosbag_storage with their names in a bag ("none", "bz2", "lz4").
inline const std::vector<std::pair<rosbag::compression::CompressionType, std::string>>&
bagCompressions() {
    static const std::vector<std::pair<rosbag::compression::CompressionType, std::string>> all = {
        {rosbag::compression::Uncompressed, "none"},
        {rosbag::compression::BZ2, "bz2"},
        {rosbag::compression::LZ4, "lz4"}};
    return all;
}

/// The compressions named by the chunk records of the bag at `path` ("none", "bz2", "lz4").
inline std::set<std::string> chunkCompressions(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    std::set<std::string> found;
    for (const std::string c : {"none", "bz2", "lz4"})
        if (bytes.find("compression=" + c) != std::string::npos) found.insert(c);
    return found;
}

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
