#include "kfd/ros2/type_hash.h"

#include <openssl/sha.h>

#include <map>
#include <set>
#include <stdexcept>
#include <vector>

namespace kfd::ros2 {

namespace {

// type_description_interfaces/msg/FieldType ids.
enum TypeId : int {
    kNested = 1,
    kInt32 = 6,
    kUint32 = 7,
    kFloat32 = 10,
    kFloat64 = 11,
    kByte = 16,
    kString = 17,
    kArray = 48,      // added to an element id: a fixed array (capacity = its size)
    kSequence = 144,  // added to an element id: an unbounded sequence
};

struct Field {
    const char* name;
    int type_id;
    int capacity = 0;
    const char* nested = "";
};

Field nested(const char* name, const char* type) { return {name, kNested, 0, type}; }

const std::map<std::string, std::vector<Field>>& descriptions() {
    static const std::map<std::string, std::vector<Field>> kTypes = {
        {"builtin_interfaces/msg/Time", {{"sec", kInt32}, {"nanosec", kUint32}}},
        {"std_msgs/msg/Header",
         {nested("stamp", "builtin_interfaces/msg/Time"), {"frame_id", kString}}},
        {"sensor_msgs/msg/LaserScan",
         {nested("header", "std_msgs/msg/Header"),
          {"angle_min", kFloat32},
          {"angle_max", kFloat32},
          {"angle_increment", kFloat32},
          {"time_increment", kFloat32},
          {"scan_time", kFloat32},
          {"range_min", kFloat32},
          {"range_max", kFloat32},
          {"ranges", kFloat32 + kSequence},
          {"intensities", kFloat32 + kSequence}}},
        {"geometry_msgs/msg/Point", {{"x", kFloat64}, {"y", kFloat64}, {"z", kFloat64}}},
        {"geometry_msgs/msg/Vector3", {{"x", kFloat64}, {"y", kFloat64}, {"z", kFloat64}}},
        {"geometry_msgs/msg/Quaternion",
         {{"x", kFloat64}, {"y", kFloat64}, {"z", kFloat64}, {"w", kFloat64}}},
        {"geometry_msgs/msg/Pose",
         {nested("position", "geometry_msgs/msg/Point"),
          nested("orientation", "geometry_msgs/msg/Quaternion")}},
        {"geometry_msgs/msg/PoseWithCovariance",
         {nested("pose", "geometry_msgs/msg/Pose"), {"covariance", kFloat64 + kArray, 36}}},
        {"geometry_msgs/msg/Twist",
         {nested("linear", "geometry_msgs/msg/Vector3"),
          nested("angular", "geometry_msgs/msg/Vector3")}},
        {"geometry_msgs/msg/TwistWithCovariance",
         {nested("twist", "geometry_msgs/msg/Twist"), {"covariance", kFloat64 + kArray, 36}}},
        {"nav_msgs/msg/Odometry",
         {nested("header", "std_msgs/msg/Header"),
          {"child_frame_id", kString},
          nested("pose", "geometry_msgs/msg/PoseWithCovariance"),
          nested("twist", "geometry_msgs/msg/TwistWithCovariance")}},
        {"geometry_msgs/msg/Transform",
         {nested("translation", "geometry_msgs/msg/Vector3"),
          nested("rotation", "geometry_msgs/msg/Quaternion")}},
        {"geometry_msgs/msg/TransformStamped",
         {nested("header", "std_msgs/msg/Header"),
          {"child_frame_id", kString},
          nested("transform", "geometry_msgs/msg/Transform")}},
        {"tf2_msgs/msg/TFMessage",
         {{"transforms", kNested + kSequence, 0, "geometry_msgs/msg/TransformStamped"}}},
        {"diagnostic_msgs/msg/KeyValue", {{"key", kString}, {"value", kString}}},
        {"diagnostic_msgs/msg/DiagnosticStatus",
         {{"level", kByte},
          {"name", kString},
          {"message", kString},
          {"hardware_id", kString},
          {"values", kNested + kSequence, 0, "diagnostic_msgs/msg/KeyValue"}}},
        {"diagnostic_msgs/msg/DiagnosticArray",
         {nested("header", "std_msgs/msg/Header"),
          {"status", kNested + kSequence, 0, "diagnostic_msgs/msg/DiagnosticStatus"}}},
    };
    return kTypes;
}

const std::vector<Field>& fieldsOf(const std::string& type) {
    const auto it = descriptions().find(type);
    if (it == descriptions().end())
        throw std::invalid_argument("no ROS 2 type description for '" + type + "'");
    return it->second;
}

void referenced(const std::string& type, std::set<std::string>& out) {
    for (const Field& f : fieldsOf(type))
        if (*f.nested && out.insert(f.nested).second) referenced(f.nested, out);
}

// One IndividualTypeDescription as rosidl's json.dumps writes it (separators ", " and ": ").
std::string individual(const std::string& type) {
    std::string s = "{\"type_name\": \"" + type + "\", \"fields\": [";
    bool first = true;
    for (const Field& f : fieldsOf(type)) {
        s += first ? "" : ", ";
        first = false;
        s += "{\"name\": \"" + std::string(f.name) +
             "\", \"type\": {\"type_id\": " + std::to_string(f.type_id) +
             ", \"capacity\": " + std::to_string(f.capacity) +
             ", \"string_capacity\": 0, \"nested_type_name\": \"" + f.nested + "\"}}";
    }
    return s + "]}";
}

}  // namespace

std::string typeDescriptionJson(const std::string& ros2_type) {
    std::set<std::string> refs;  // sorted by name, as rosidl sorts them
    referenced(ros2_type, refs);
    std::string s =
        "{\"type_description\": " + individual(ros2_type) + ", \"referenced_type_descriptions\": [";
    bool first = true;
    for (const std::string& r : refs) {
        s += (first ? "" : ", ") + individual(r);
        first = false;
    }
    return s + "]}";
}

std::string typeHash(const std::string& ros2_type) {
    const std::string json = typeDescriptionJson(ros2_type);
    unsigned char digest[SHA256_DIGEST_LENGTH];
    SHA256(reinterpret_cast<const unsigned char*>(json.data()), json.size(), digest);
    static const char* hex = "0123456789abcdef";
    std::string out = "RIHS01_";
    for (unsigned char b : digest) {
        out += hex[b >> 4];
        out += hex[b & 15];
    }
    return out;
}

std::string ddsTypeName(const std::string& ros2_type) {
    const auto a = ros2_type.find("/msg/");
    if (a == std::string::npos)
        throw std::invalid_argument("not a ROS 2 message type: " + ros2_type);
    return ros2_type.substr(0, a) + "::msg::dds_::" + ros2_type.substr(a + 5) + "_";
}

}  // namespace kfd::ros2
