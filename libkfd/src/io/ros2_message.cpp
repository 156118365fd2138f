#include "kfd/io/ros2_message.h"

#include <map>

#include "cdr.h"
#include "kfd/io/bag_source.h"

namespace kfd {
namespace {

// The smallest CDR size of one TransformStamped (two empty strings, no padding): a sequence
// count above (bytes left) / this cannot be true.
constexpr std::size_t kMinTransformBytes = 72;

void readHeader(CdrReader& r, std_msgs::Header& h) {
    const std::int32_t sec = r.read<std::int32_t>("header.stamp.sec");
    const std::uint32_t nsec = r.read<std::uint32_t>("header.stamp.nanosec");
    if (sec < 0 || nsec >= 1000000000u)
        throw CdrError("header.stamp: " + std::to_string(sec) + " s " + std::to_string(nsec) +
                       " ns is not a time (a negative second, or nanoseconds of 1e9 or more)");
    h.seq = 0;
    h.stamp.sec = static_cast<std::uint32_t>(sec);
    h.stamp.nsec = nsec;
    h.frame_id = r.readString("header.frame_id");
}

void readPoint(CdrReader& r, double& x, double& y, double& z, const char* field) {
    x = r.read<double>(field);
    y = r.read<double>(field);
    z = r.read<double>(field);
}

void readQuaternion(CdrReader& r, geometry_msgs::Quaternion& q, const char* field) {
    q.x = r.read<double>(field);
    q.y = r.read<double>(field);
    q.z = r.read<double>(field);
    q.w = r.read<double>(field);
}

template <class Fn>
void decodeAs(const char* type, const std::uint8_t* data, std::size_t size, Fn&& fn) {
    try {
        CdrReader r(data, size);
        fn(r);
    } catch (const CdrError& e) {
        throw BagError(std::string("corrupt ") + type + ": " + e.what());
    }
}

void writeHeader(CdrWriter& w, const std_msgs::Header& h) {
    w.write<std::int32_t>(static_cast<std::int32_t>(h.stamp.sec));
    w.write<std::uint32_t>(h.stamp.nsec);
    w.writeString(h.frame_id);
}

void writeQuaternion(CdrWriter& w, const geometry_msgs::Quaternion& q) {
    w.write(q.x);
    w.write(q.y);
    w.write(q.z);
    w.write(q.w);
}

const char* const kHeaderDef =
    "================================================================================\n"
    "MSG: std_msgs/Header\n"
    "builtin_interfaces/Time stamp\n"
    "string frame_id\n"
    "================================================================================\n"
    "MSG: builtin_interfaces/Time\n"
    "int32 sec\n"
    "uint32 nanosec\n";

}  // namespace

std::string ros1TypeName(const std::string& type) {
    const auto at = type.find("/msg/");
    if (at == std::string::npos || type.find('/', at + 5) != std::string::npos) return type;
    return type.substr(0, at) + "/" + type.substr(at + 5);
}

void decodeRos2(const std::uint8_t* data, std::size_t size, sensor_msgs::LaserScan& m) {
    decodeAs("sensor_msgs/msg/LaserScan", data, size, [&](CdrReader& r) {
        readHeader(r, m.header);
        m.angle_min = r.read<float>("angle_min");
        m.angle_max = r.read<float>("angle_max");
        m.angle_increment = r.read<float>("angle_increment");
        m.time_increment = r.read<float>("time_increment");
        m.scan_time = r.read<float>("scan_time");
        m.range_min = r.read<float>("range_min");
        m.range_max = r.read<float>("range_max");
        r.readSequence(m.ranges, "ranges");
        r.readSequence(m.intensities, "intensities");
    });
}

void decodeRos2(const std::uint8_t* data, std::size_t size, nav_msgs::Odometry& m) {
    decodeAs("nav_msgs/msg/Odometry", data, size, [&](CdrReader& r) {
        readHeader(r, m.header);
        m.child_frame_id = r.readString("child_frame_id");
        auto& p = m.pose.pose;
        readPoint(r, p.position.x, p.position.y, p.position.z, "pose.pose.position");
        readQuaternion(r, p.orientation, "pose.pose.orientation");
        for (double& c : m.pose.covariance) c = r.read<double>("pose.covariance");
        auto& t = m.twist.twist;
        readPoint(r, t.linear.x, t.linear.y, t.linear.z, "twist.twist.linear");
        readPoint(r, t.angular.x, t.angular.y, t.angular.z, "twist.twist.angular");
        for (double& c : m.twist.covariance) c = r.read<double>("twist.covariance");
    });
}

void decodeRos2(const std::uint8_t* data, std::size_t size, tf2_msgs::TFMessage& m) {
    decodeAs("tf2_msgs/msg/TFMessage", data, size, [&](CdrReader& r) {
        m.transforms.resize(r.readCount("transforms", kMinTransformBytes));
        for (auto& t : m.transforms) {
            readHeader(r, t.header);
            t.child_frame_id = r.readString("transforms.child_frame_id");
            auto& p = t.transform.translation;
            readPoint(r, p.x, p.y, p.z, "transforms.transform.translation");
            readQuaternion(r, t.transform.rotation, "transforms.transform.rotation");
        }
    });
}

void decodeRos2(const std::uint8_t* data, std::size_t size, diagnostic_msgs::DiagnosticArray& m) {
    decodeAs("diagnostic_msgs/msg/DiagnosticArray", data, size, [&](CdrReader& r) {
        readHeader(r, m.header);
        // A status is at least its level and three empty strings (1 + 3 + 3 x 5 bytes).
        m.status.resize(r.readCount("status", 19));
        for (auto& s : m.status) {
            s.level = r.read<std::uint8_t>("status.level");
            s.name = r.readString("status.name");
            s.message = r.readString("status.message");
            s.hardware_id = r.readString("status.hardware_id");
            s.values.resize(r.readCount("status.values", 10));  // two empty strings
            for (auto& kv : s.values) {
                kv.key = r.readString("status.values.key");
                kv.value = r.readString("status.values.value");
            }
        }
    });
}

std::vector<std::uint8_t> encodeRos2(const sensor_msgs::LaserScan& m) {
    CdrWriter w;
    writeHeader(w, m.header);
    for (float v : {m.angle_min, m.angle_max, m.angle_increment, m.time_increment, m.scan_time,
                    m.range_min, m.range_max})
        w.write(v);
    w.writeSequence(m.ranges);
    w.writeSequence(m.intensities);
    return std::move(w.bytes());
}

std::vector<std::uint8_t> encodeRos2(const nav_msgs::Odometry& m) {
    CdrWriter w;
    writeHeader(w, m.header);
    w.writeString(m.child_frame_id);
    const auto& p = m.pose.pose;
    for (double v : {p.position.x, p.position.y, p.position.z}) w.write(v);
    writeQuaternion(w, p.orientation);
    for (double c : m.pose.covariance) w.write(c);
    const auto& t = m.twist.twist;
    for (double v : {t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z})
        w.write(v);
    for (double c : m.twist.covariance) w.write(c);
    return std::move(w.bytes());
}

std::vector<std::uint8_t> encodeRos2(const tf2_msgs::TFMessage& m) {
    CdrWriter w;
    w.write<std::uint32_t>(static_cast<std::uint32_t>(m.transforms.size()));
    for (const auto& t : m.transforms) {
        writeHeader(w, t.header);
        w.writeString(t.child_frame_id);
        const auto& p = t.transform.translation;
        for (double v : {p.x, p.y, p.z}) w.write(v);
        writeQuaternion(w, t.transform.rotation);
    }
    return std::move(w.bytes());
}

std::vector<std::uint8_t> encodeRos2(const diagnostic_msgs::DiagnosticArray& m) {
    CdrWriter w;
    writeHeader(w, m.header);
    w.write<std::uint32_t>(static_cast<std::uint32_t>(m.status.size()));
    for (const auto& s : m.status) {
        w.write<std::uint8_t>(s.level);
        w.writeString(s.name);
        w.writeString(s.message);
        w.writeString(s.hardware_id);
        w.write<std::uint32_t>(static_cast<std::uint32_t>(s.values.size()));
        for (const auto& kv : s.values) {
            w.writeString(kv.key);
            w.writeString(kv.value);
        }
    }
    return std::move(w.bytes());
}

const std::string& ros2Definition(const std::string& ros2_type) {
    static const std::map<std::string, std::string> kDefs = {
        {"sensor_msgs/msg/LaserScan",
         std::string("std_msgs/Header header\n"
                     "float32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\n"
                     "float32 time_increment\nfloat32 scan_time\n"
                     "float32 range_min\nfloat32 range_max\n"
                     "float32[] ranges\nfloat32[] intensities\n") +
             kHeaderDef},
        {"nav_msgs/msg/Odometry",
         std::string("std_msgs/Header header\nstring child_frame_id\n"
                     "geometry_msgs/PoseWithCovariance pose\n"
                     "geometry_msgs/TwistWithCovariance twist\n") +
             kHeaderDef +
             "================================================================================\n"
             "MSG: geometry_msgs/PoseWithCovariance\n"
             "geometry_msgs/Pose pose\nfloat64[36] covariance\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Pose\ngeometry_msgs/Point position\n"
             "geometry_msgs/Quaternion orientation\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\n"
             "float64 w 1\n"
             "================================================================================\n"
             "MSG: geometry_msgs/TwistWithCovariance\n"
             "geometry_msgs/Twist twist\nfloat64[36] covariance\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Twist\ngeometry_msgs/Vector3 linear\n"
             "geometry_msgs/Vector3 angular\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"},
        {"tf2_msgs/msg/TFMessage",
         std::string(
             "geometry_msgs/TransformStamped[] transforms\n"
             "================================================================================\n"
             "MSG: geometry_msgs/TransformStamped\n"
             "std_msgs/Header header\nstring child_frame_id\n"
             "geometry_msgs/Transform transform\n") +
             kHeaderDef +
             "================================================================================\n"
             "MSG: geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\n"
             "geometry_msgs/Quaternion rotation\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
             "================================================================================\n"
             "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\n"
             "float64 w 1\n"},
    };
    static const std::string kNone;
    const auto it = kDefs.find(ros2_type);
    return it == kDefs.end() ? kNone : it->second;
}

}  // namespace kfd
