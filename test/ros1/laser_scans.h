// Hand-made sensor_msgs/LaserScan messages for the ROS 1 node's tests.
#pragma once

#include <sensor_msgs/LaserScan.h>

#include <cmath>
#include <cstddef>
#include <string>

namespace kfd::test {

/// A scan from the middle of a 4 m x 6 m room (robot at its centre, facing +x), `beams` beams
/// over 180 degrees, stamped `stamp` s, frame `frame`; `shift` m moves the robot along +x.
inline sensor_msgs::LaserScan roomScan(double stamp, const std::string& frame = "laser",
                                       std::size_t beams = 181, double shift = 0.0) {
    sensor_msgs::LaserScan m;
    m.header.stamp.fromSec(stamp);
    m.header.frame_id = frame;
    m.angle_min = static_cast<float>(-M_PI / 2);
    m.angle_max = static_cast<float>(M_PI / 2);
    m.angle_increment = static_cast<float>(M_PI / double(beams - 1));
    m.range_min = 0.05f;
    m.range_max = 30.0f;
    m.scan_time = 0.1f;
    m.ranges.resize(beams);
    const double hx = 3.0 - shift, hy = 2.0;  // distances to the front and side walls
    for (std::size_t i = 0; i < beams; ++i) {
        const double a = double(m.angle_min) + double(i) * double(m.angle_increment);
        const double c = std::cos(a), s = std::sin(a);
        double r = 1e9;
        if (c > 1e-9) r = std::min(r, hx / c);
        if (std::fabs(s) > 1e-9) r = std::min(r, hy / std::fabs(s));
        m.ranges[i] = static_cast<float>(r);
    }
    return m;
}

}  // namespace kfd::test
