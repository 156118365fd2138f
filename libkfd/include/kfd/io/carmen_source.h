// The CARMEN log source: .clf / .log text logs, plain or gzip.
#pragma once

#include <memory>
#include <string>

#include "kfd/io/source.h"
#include "kfd/io/source_listing.h"

namespace kfd {

/// A CARMEN log that cannot be read: a line with the wrong number of fields or a field that is
/// not a number (the message names the file, the line number and the field).
class CarmenError : public SourceError {
  public:
    using SourceError::SourceError;
};

/// Reads a CARMEN log line by line (never loaded whole), plain or gzip (the gzip stream's end
/// is checked like a rawlog's). Each line is one message with its own timestamp (the
/// ipc_timestamp field):
///  - FLASER / RLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_ts host logger_ts: an
///    Observation entry with a CObservationOdometry (label "ODOMETRY", the odom_* pose), then
///    one with the scan (label "FLASER" / "RLASER"). As MRPT's carmen2rawlog converts them, so
///    that the log and its rawlog give the same scans: aperture = resolution x n (PARAM
///    laser_front_laser_resolution / laser_rear_laser_resolution; without it the SICK
///    resolution of 1, 0.5 or 0.25 deg within 1 % of 180 deg / n, else 180 deg / n: 0.5 deg
///    for 361 beams as carmen2rawlog, 1 deg for 180 beams where carmen2rawlog's fixed 0.5 deg
///    gives 90 deg), max range from PARAM robot_front_laser_max / robot_rear_laser_max
///    (default 81 m), a beam valid
///    when 0 < r < max, sensor pose = the laser pose x y theta in the frame of the odometry
///    pose (unless PARAM robot_frontlaser_offset / robot_rearlaser_offset give the mount).
///  - RAWLASER1..4 (laser_type start_angle fov resolution max_range accuracy remission_mode n
///    r1..rn n_rem rem.. ipc_ts host logger_ts): a scan without odometry (label RAWLASERk),
///    beams from start_angle over fov.
///  - ROBOTLASER1/2 (the RAWLASER fields, then laser pose, robot pose, tv rv forward_safety
///    side_safety turn_axis, ipc_ts host logger_ts): odometry (the robot pose) and a scan
///    (label ROBOTLASERk) mounted at the laser pose in the robot's frame.
///  - ODOM x y theta tv rv accel ipc_ts host logger_ts: a CObservationOdometry.
///  - PARAM name value [host ts]: applies to the lines after it.
///  - comments (#), empty lines and other keywords (TRUEPOS, SYNC, ...) are skipped.
///  - a line that is not CARMEN text (a control character other than a tab, a byte above 127
///    outside a comment, a first field that is not an upper-case keyword: binary data, another
///    format) is skipped and counted (SourceCounters::lines_unparsable, bytes_unparsable,
///    first_unparsable_line). When such lines hold more bytes than all the other lines, the
///    log is refused at its end ("most of the log is not CARMEN text").
/// A line with the wrong field count or a bad number is a CarmenError ("file:LINE: FLASER
/// with 361 readings has 370 fields, expected 372"), and so is a laser mount that is not finite
/// (a FLASER's laser pose or odometry, a RAWLASER's start angle or field of view, a
/// ROBOTLASER's laser or robot pose: "file:LINE: FLASER laser pose ... is not finite") or a
/// PARAM kfd uses (laser offsets, range, resolution) that is not finite. A reading or remission
/// count is checked against the fields after it on its line before a scan is sized by it
/// ("FLASER reading count 1073741824 is more than the 11 fields after it"; at most 1 000 000); a
/// line longer than 64 MiB or of more than 2 000 100 fields is refused, so no input makes the
/// reader hold more than ~100 MB.
class CarmenSource : public Source {
  public:
    explicit CarmenSource(const std::string& path);
    ~CarmenSource() override;
    CarmenSource(const CarmenSource&) = delete;
    CarmenSource& operator=(const CarmenSource&) = delete;

    bool next(SourceEntry& e) override;
    const std::string& path() const override;
    std::uint64_t bytesRead() const override;
    std::uint64_t bytesTotal() const override;
    /// Lines read so far (the number of the last line read).
    std::size_t line() const;
    /// The lines that are not CARMEN text, skipped so far.
    SourceCounters counters() const override;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The CARMEN part of listSource(): the line keywords with counts and stamp ranges, and the
/// PARAM values.
SourceListing listCarmen(const std::string& path);

}  // namespace kfd
