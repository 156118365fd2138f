// Writing a filtered ROS 1 bag: the input's messages copied in order, the kept scans written
// with their removed points marked (REP 117).
#pragma once

#include <mrpt/obs/CObservation2DRangeScan.h>

#include <memory>
#include <string>

#include "kfd/io/bag_source.h"

namespace kfd {

/// How a point kfd removed from a kept scan is written (REP 117, "Informational Distance
/// Measurements"): NaN, "an erroneous or invalid measurement" (the default, and what ROS's
/// laser_filters write for filtered points), or +Inf, "no object detected in range" (for
/// consumers that treat only +Inf as "ignore").
enum class RemovedMark { NaN, PlusInf };
const char* toString(RemovedMark m);
/// "nan" or "inf"; throws kfd::Error on anything else.
RemovedMark parseRemovedMark(const std::string& text);

struct BagWriterOptions {
    /// The chunks' compression. AsInput: the input bag's (BagSource::compression(); what
    /// RawlogFilter resolves it to; a BagWriter given AsInput writes uncompressed chunks).
    /// MCAP outputs: none, lz4 or zstd chunks (AsInput: the input's when it is one of these,
    /// else zstd); a .db3 is not compressed; zstd is MCAP's only (a ROS 1 bag refuses it).
    enum class Compression { AsInput, None, Lz4, Bz2, Zstd } compression = Compression::AsInput;
    RemovedMark removed = RemovedMark::NaN;
};

/// "input", "none", "lz4", "bz2" or "zstd" (a bag's chunk compression, BagSource::compression());
/// throws kfd::Error on anything else.
BagWriterOptions::Compression parseBagCompression(const std::string& text);
/// parseBagCompression's text: "input", "none", "lz4", "bz2" or "zstd".
const char* toString(BagWriterOptions::Compression c);

/// A bag output of kfd-filter, whatever its format (BagWriter: ROS 1; Ros2Writer: rosbag2's
/// .db3 or MCAP, kfd/io/ros2_writer.h): the input's messages copied, the kept scans written.
class MessageWriter {
  public:
    virtual ~MessageWriter() = default;
    virtual void copy(const NativeMessage& message) = 0;
    virtual std::size_t writeScan(const NativeMessage& original,
                                  const mrpt::obs::CObservation2DRangeScan& cleaned) = 0;
    virtual void close() = 0;
    virtual std::size_t messagesWritten() const = 0;
};

/// Writes a bag (format 2.0) from messages of a BagSource's bag. Errors are BagErrors whose
/// first words say what failed: "cannot write out.bag: No space left on device (rosbag: ...)".
class BagWriter : public MessageWriter {
  public:
    /// Opens `path` for writing; BagError when it cannot be created. `name` is the file users
    /// know, for messages (the final name of a temporary file; `path` when empty).
    BagWriter(const std::string& path, const BagWriterOptions& options = {},
              const std::string& name = {});
    ~BagWriter() override;
    BagWriter(const BagWriter&) = delete;
    BagWriter& operator=(const BagWriter&) = delete;

    /// Copies a message unchanged: same topic, bag time, bytes and connection header.
    void copy(const NativeMessage& message) override;
    /// Writes the LaserScan `original` (topic, bag time, header and every field kept) with the
    /// range of each beam that was valid in it (finite, range_min <= r < range_max) and that
    /// `cleaned` marks invalid replaced by the removed mark; other beams are left as they were.
    /// Returns the number of beams marked.
    std::size_t writeScan(const NativeMessage& original,
                          const mrpt::obs::CObservation2DRangeScan& cleaned) override;
    /// Writes the index and closes the file, then opens the bag again and checks that its
    /// index holds every message written (rosbag ignores some write errors); BagError on any
    /// failure.
    void close() override;
    std::size_t messagesWritten() const override;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace kfd
