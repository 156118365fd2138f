// Tiny hand-made ROS 1 bags for the tests (written with Debian's rosbag_storage).
#pragma once

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_msgs/TFMessage.h>

#include <cmath>
#include <string>
#include <vector>

namespace kfd {
namespace test {

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
