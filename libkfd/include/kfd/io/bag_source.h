// The ROS 1 bag source: sensor_msgs/LaserScan scans with odometry from nav_msgs/Odometry or
// /tf, the laser mount from /tf_static; plain, bz2 or lz4 bags (Debian's rosbag_storage).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "kfd/io/source.h"
#include "kfd/io/source_listing.h"

namespace kfd {

/// A bag that cannot be read or used: not a bag, truncated, unindexed or corrupt; a topic that
/// is missing or of the wrong type; a bag without a usable LaserScan topic; a laser mount in
/// /tf_static that is not finite.
class BagError : public SourceError {
  public:
    using SourceError::SourceError;
};

/// Walks every record of a ROS bag 2.0 file (headers, chunks decompressed, the records inside
/// them, the index entries and the chunk index) and throws BagError naming the file, the byte
/// offset and what is wrong: not a bag, truncated, no index, a chunk that does not decompress,
/// a length or an offset outside its record or chunk. rosbag_storage trusts these, so
/// listBag() and BagSource run this check first (the index only), and check each chunk's contents
/// (its records, the index entries into it) when it first reads the chunk, so that each chunk is
/// decompressed once (a corrupt chunk is then a BagError from next(), naming its byte, as
/// here). kfd reads the chunks itself; rosbag_storage only reads the index. A compressed
/// chunk's output grows with what its data holds, up to its announced size: a corrupt size
/// field allocates nothing. (The lengths inside a message are checked when it is read, see
/// BagSource; other corrupt bytes inside a message's data, e.g. a range value, cannot be told
/// from real data: bags carry no checksums.)
void checkBagStructure(const std::string& path);

/// What a BagSource reads from its bag (after the automatic choices).
struct BagChoice {
    std::string scan_topic;
    enum class Odometry { None, Topic, Tf } odometry = Odometry::None;
    std::string odom_topic;  // Topic: the nav_msgs/Odometry topic
    std::string odom_frame, base_frame;
    std::string laser_frame;   // header.frame_id of the first scan ("" = unknown yet)
    bool mount_found = false;  // base -> laser found in /tf_static (else identity)
    double mount_x = 0.0, mount_y = 0.0, mount_yaw = 0.0;  // metres, radians
    /// How each choice was made, one line each ("scans: /scan (the only LaserScan topic)").
    std::vector<std::string> notes;
    /// Topics of scans kfd does not read (sensor_msgs/MultiEchoLaserScan), as "TOPIC (TYPE,
    /// N messages)": a bag output copies them as they are, unfiltered.
    std::vector<std::string> unread_scans;
};

/// Reads a ROS 1 bag (format 2.0, any chunk compression) message by message in time order,
/// through the bag's index (a bag whose index is missing, i.e. one cut short while recording,
/// is refused: `rosbag reindex` repairs it). The order is rosbag::View's; each chunk is
/// decompressed once (the chunks of the messages held for a scan's odometry stay in a cache of
/// at most 64 MiB, freed as soon as the pass has read all their messages), and each message is
/// copied out of its chunk, so writing it reads nothing again.
///
/// Choices (SourceOptions; a named topic must exist and have the right type, else BagError):
///  - scans: the --scan-topic, else the only sensor_msgs/LaserScan topic, else /scan or scan
///    among several, else BagError listing them.
///  - odometry: --odom-topic (a nav_msgs/Odometry topic, "tf" or "none"); else the only
///    Odometry topic (/odom among several), else /tf when it holds transforms from the odom
///    frame, else none (laser only). A scan's odometry is the odometry interpolated at its
///    header stamp (linearly, the heading along the shorter arc) between the last message at
///    or before it and the first after it; up to 1 s before the first message it is the first,
///    up to 1 s after the last the last (the rule of the datasets' bag2clf.py, so a bag and the
///    rawlog made from it give the same poses). Further outside the odometry's time span (a
///    header stamp of another clock, odometry that starts late or stops early) the scan's
///    odometry is unknown (no odometry observation before it), counted
///    (SourceCounters::scans_without_odometry). The source looks ahead at most 10 s of bag time
///    (or 100 000 messages, or 256 MiB of messages) for the message after a scan, then holds the
///    last one (within 1 s).
///  - stamps: a header stamp of 0 (unset) is replaced by the message's bag record time, for
///    scans and odometry alike (counted: SourceCounters::stamps_zero).
///  - mount: the chain of /tf_static transforms from the base frame to the scan's frame_id
///    (leading '/' ignored), composed in 2D; identity when there is none. A transform of that
///    chain that is not finite (or a rotation of norm 0) is a BagError naming the frames.
///
/// Entries: each scan is an Observation entry with a CObservation2DRangeScan (label = topic
/// without its leading '/', stamp = header.stamp, aperture = angle_max - angle_min, direction
/// from the sign of angle_increment, sensor pose = mount + the yaw of the beams' middle,
/// maxRange = range_max, intensities when there is one per beam). Angle fields that do not
/// match the beam count (not finite, an increment of 0, (angle_max - angle_min) /
/// angle_increment more than one beam away from n - 1, which includes an increment of the wrong
/// sign) give the scan an aperture of NaN: the door skips it (bad_aperture), and the source
/// counts it (SourceCounters::scans_bad_angles). A beam is valid when its
/// range is finite and range_min <= r < range_max (r = range_max is taken as "no return", as
/// MRPT's CARMEN and rawlog conventions do); invalid non-finite ranges are stored as 0.
/// With odometry, each scan is preceded by an Observation entry with a CObservationOdometry
/// (label "ODOMETRY", the scan's stamp and interpolated pose), the layout of kfd's rawlogs.
/// Every message, the scans' included, also travels as `native` (scans) or as a Native entry
/// (all other messages, odometry ones too), in the bag's order.
///
/// Corrupt messages: before a LaserScan, Odometry or TFMessage is deserialized, every string
/// and array length in its bytes is checked against the bytes left of the message (roscpp
/// resizes to the length it reads before it finds the bytes missing: 8.4 GB for a ranges
/// length of 0x40000000). A length that does not fit is a BagError naming the file, the
/// message (its number in next(), its topic and time), the type, the field and both sizes:
/// "message 12 (/scan at t = 2.100000 s): corrupt sensor_msgs/LaserScan: ranges: array length
/// 1073741824 (4294967296 bytes) does not fit in the message's 781 bytes (728 left)". Messages
/// of other types are copied, never deserialized.
class BagSource : public Source {
  public:
    /// Opens `path` and makes the choices; BagError naming the file and the reason.
    BagSource(const std::string& path, const SourceOptions& options = {});
    ~BagSource() override;
    BagSource(const BagSource&) = delete;
    BagSource& operator=(const BagSource&) = delete;

    bool next(SourceEntry& e) override;
    const std::string& path() const override;
    /// Progress by messages: the file size times the share of messages read.
    std::uint64_t bytesRead() const override;
    std::uint64_t bytesTotal() const override;

    const BagChoice& choice() const;
    /// Angle fields that do not match the beam count, stamps of 0, scans without odometry.
    SourceCounters counters() const override;
    /// The bag's chunks, and how many have been loaded (decompressed, when compressed) so far:
    /// each once when the bag is read through (the chunks of messages read when the bag is
    /// opened stay cached for the pass), unless its messages interleave with those of other
    /// chunks over more than 64 MiB of decompressed chunks.
    std::size_t chunks() const;
    std::size_t chunksLoaded() const;
    /// The compression of the bag's chunks ("none", "bz2" or "lz4"; of most of them when they
    /// differ): what a bag output takes by default (BagWriterOptions::Compression::AsInput).
    std::string compression() const;
    /// "ROS 1 bag", "rosbag2 (sqlite3)" or "MCAP".
    std::string kind() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The bag part of listSource(): topics with types, counts and stamp ranges, and the choices a
/// BagSource would make with `options` (a choice that fails is listed as such).
SourceListing listBag(const std::string& path, const SourceOptions& options = {});

}  // namespace kfd
