// Writing a CARMEN log: the scans as FLASER / RLASER lines and the odometry as ODOM lines, in
// the order given (kfd-filter's output for a name ending in .clf or .log, .clf.gz / .log.gz for
// gzip). Read back by kfd's CarmenSource and by MRPT's carmen2rawlog.
#pragma once

#include <mrpt/obs/CObservation2DRangeScan.h>

#include <filesystem>
#include <memory>
#include <string>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// A scan a CARMEN log cannot hold: one without odometry (a FLASER line carries the robot's
/// odometry pose), or of a third laser (FLASER and RLASER are the two CARMEN has).
class CarmenWriteError : public Error {
  public:
    using Error::Error;
};

/// True for the names kfd writes as a CARMEN log: .clf, .log, .clf.gz, .log.gz (letter case
/// aside).
bool isCarmenOutputName(const std::string& path);

/// Writes a CARMEN log (the format of carmen's logger and of the Freiburg/Radish logs: one
/// message a line, "message fields... ipc_timestamp ipc_hostname logger_timestamp"):
///  - a header of '#' comment lines (the writer, the line formats, `origin`);
///  - per laser, before its first scan and whenever they change, PARAM robot_front_laser_max
///    (the scan's maxRange) and PARAM laser_front_laser_resolution (aperture / beams, in deg;
///    rear: robot_rear_laser_max, laser_rear_laser_resolution): what CarmenSource and MRPT's
///    carmen2rawlog read the scan's range and aperture (= resolution x beams) from;
///  - FLASER n r1..rn x y theta odom_x odom_y odom_theta t kfd t for the first laser label
///    written, RLASER for the second: beams right to left (a left-to-right scan is reversed);
///    x y theta is the laser's pose, odom (+) the scan's sensorPose in 2D (both readers take
///    the mount as laser (-) odom). A valid beam is written with its range; an invalid one
///    (marked invalid by kfd, or invalid in the input) as 0, CARMEN's "no reading" that
///    CarmenSource, carmen2rawlog and grid mappers skip, unless its range is already at or above
///    the max range (a "no return" reading, kept as it was). Numbers are written in their
///    shortest exact form, so a scan reads back with the same float ranges;
///  - ODOM x y theta 0 0 0 t kfd t (velocities and acceleration unknown: 0).
/// Every write goes through kfd's checked writers (OutputFile; GzOutputStream for gzip): a
/// failed write is a WriteError naming `name` ("cannot write out.clf: No space left on
/// device"); close() ends the file (gzip trailer, fsync) and checks it.
class CarmenWriter {
  public:
    /// Creates `path` (gzip at `level` 0-9 when `gzip`); `name` is the file users know (the
    /// final name of a temporary; `path` when empty). WriteError when it cannot be created.
    CarmenWriter(const std::filesystem::path& path, const std::string& name, bool gzip,
                 int level = 6, const std::string& origin = {});
    ~CarmenWriter();
    CarmenWriter(const CarmenWriter&) = delete;
    CarmenWriter& operator=(const CarmenWriter&) = delete;

    /// An ODOM line at `stamp` (s).
    void writeOdometry(const Pose2D& odometry, double stamp);
    /// A FLASER or RLASER line for `scan` with the robot's absolute `odometry`. Throws
    /// CarmenWriteError for a third laser label.
    void writeScan(const mrpt::obs::CObservation2DRangeScan& scan, const Pose2D& odometry);
    /// Ends and closes the file, checked (WriteError).
    void close();
    std::size_t linesWritten() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace kfd
