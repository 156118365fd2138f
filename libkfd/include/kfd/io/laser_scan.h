// The one conversion of a sensor_msgs/LaserScan to and from kfd's MRPT scan: the bag source
// (kfd-filter -i X.bag), the bag writer and the ROS 1 node use these functions, so the node's
// decisions equal kfd-filter's on the same bag. Needs the ROS 1 message headers (kfd is always
// built with them: cmake/FindKfdRos1.cmake).
#pragma once

#include <geometry_msgs/Quaternion.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <sensor_msgs/LaserScan.h>

#include <cstddef>
#include <string>

#include "kfd/algorithms/pose.h"
#include "kfd/io/bag_writer.h"

namespace kfd {

/// The one beam validity rule of a LaserScan (the source's and the writer's): finite and
/// range_min <= r < range_max (r = range_max is "no return", as in MRPT's rawlogs and CARMEN).
bool validRange(const sensor_msgs::LaserScan& m, float r);

/// True when a LaserScan's angle fields describe its beam count: finite, an increment that is
/// not 0, and (angle_max - angle_min) / angle_increment within one beam of n - 1 (its sign
/// then matches the span's). Fewer than 2 beams: left to the door (no_beams).
bool laserAnglesMatch(const sensor_msgs::LaserScan& m);

/// True when angle_max is one increment past the last beam (angle_max - angle_min = n
/// increments, within 1e-3 of one): the convention of 360-degree drivers such as rplidar_ros
/// (0 to 2 pi in 360 beams). Such angles match the beam count too, and the beams' span is n - 1
/// increments.
bool fullTurnSpan(const sensor_msgs::LaserScan& m);

/// A tf frame's name without its leading '/'s ("/base_link" and "base_link" are one frame).
std::string frameWithoutSlash(const std::string& frame_id);

/// The yaw (rad) of a rotation given as a quaternion: how the bag source and both nodes read
/// odometry and transforms, so that they agree.
double quaternionYaw(const geometry_msgs::Quaternion& q);

/// The MRPT scan of `m` stamped `stamp` (s), labelled `label`, its laser mounted at `mount`
/// (the laser frame in the robot's base frame). Angle fields that do not match the beam count
/// (laserAnglesMatch) give an aperture of NaN: the door skips the scan (bad_aperture).
mrpt::obs::CObservation2DRangeScan::Ptr laserScanToObservation(const sensor_msgs::LaserScan& m,
                                                               double stamp,
                                                               const std::string& label,
                                                               const Pose2D& mount);

/// Marks in `m` the beams that were valid in it (validRange) and that the door left invalid in
/// `cleaned` (its MRPT scan after StreamFilter::process) with `mark` (NaN or +Inf, REP 117);
/// every other field stays as received. Returns the beams marked. When a beam_count stage
/// resampled `cleaned` (another beam count), `m` takes its beams (invalid ones marked), the
/// increment, angle_max, time_increment and intensities that go with them, and the result is
/// how many fewer valid beams it has.
std::size_t markRemovedBeams(sensor_msgs::LaserScan& m,
                             const mrpt::obs::CObservation2DRangeScan& cleaned, RemovedMark mark);

}  // namespace kfd
