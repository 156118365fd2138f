// Writing a filtered ROS 2 log: a rosbag2 sqlite3 file (.db3, Humble's schema 3) or an MCAP file
// (.mcap, ROS 2 profile), the input's messages copied in order, the kept scans written with
// their removed points marked (REP 117). kfd writes both formats itself (no rosbag2 or MCAP
// library is packaged for Debian 12).
#pragma once

#include <mrpt/obs/CObservation2DRangeScan.h>

#include <cstddef>
#include <memory>
#include <string>

#include "kfd/io/bag_writer.h"
#include "kfd/io/source.h"

namespace kfd {

/// Writes a .db3 (LogFormat::Rosbag2) or a .mcap (LogFormat::Mcap) from the messages of a
/// BagSource. A message of a ROS 2 log is copied as it came (its bytes, topic, type, encoding,
/// QoS profiles, MCAP schema); a message of a ROS 1 bag is converted to CDR when it is a
/// LaserScan, Odometry or TFMessage (the types kfd reads), and other ROS 1 messages are left out
/// and counted (their CDR form is unknown to kfd). Errors are BagErrors whose first words say
/// what failed ("cannot write out.mcap: No space left on device").
class Ros2Writer : public MessageWriter {
  public:
    /// `format`: LogFormat::Rosbag2 or LogFormat::Mcap. `name`: the file users know, for
    /// messages (the final name of a temporary file; `path` when empty).
    Ros2Writer(const std::string& path, LogFormat format, const BagWriterOptions& options = {},
               const std::string& name = {});
    ~Ros2Writer() override;
    Ros2Writer(const Ros2Writer&) = delete;
    Ros2Writer& operator=(const Ros2Writer&) = delete;

    /// Copies a message unchanged (a ROS 1 message of a type kfd reads: converted).
    void copy(const NativeMessage& m) override;
    /// Writes the LaserScan `original` with the points kfd removed from it (valid there, invalid
    /// in `cleaned`) marked; returns the points marked.
    std::size_t writeScan(const NativeMessage& original,
                          const mrpt::obs::CObservation2DRangeScan& cleaned) override;
    /// Finishes the file (the MCAP summary and footer; the sqlite transaction). BagError when
    /// it cannot be written.
    void close() override;
    std::size_t messagesWritten() const override;
    /// ROS 1 messages of types kfd cannot convert, left out.
    std::size_t messagesLeftOut() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The format a ROS 2 output name asks for: .db3 -> Rosbag2, .mcap -> Mcap; otherwise false.
bool ros2OutputFormat(const std::string& name, LogFormat& format);

}  // namespace kfd
