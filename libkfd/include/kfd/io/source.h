// The input layer: a sensor log read entry by entry, whatever its file format. The base of the
// sources: it includes none of them (kfd/io/open_source.h opens a log with the source for its
// format, kfd/io/source_listing.h lists one).
#pragma once

#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/serialization/CSerializable.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// A log that cannot be read: missing, not a log of its format, truncated or corrupt.
class SourceError : public Error {
  public:
    using Error::Error;
};

/// The one stamp rule of every source: a scan's (or any observation's) time is
/// mrpt::Clock::toDouble(timestamp), seconds since the UNIX epoch; an observation without a
/// timestamp (a default-constructed mrpt::Clock::time_point) has time NaN ("unknown", as in
/// kfd::Scan::timestamp).
double stampOf(const mrpt::obs::CObservation& obs);

/// For text outputs that need a number (stats CSV, scans.csv, trajectory.tum): an unknown
/// (NaN) time is written as 0.
inline double stampForOutput(double stamp) { return stamp == stamp ? stamp : 0.0; }

/// True when x, y and phi are all finite.
bool finitePose(double x, double y, double phi);

/// The one odometry tracker: the robot's absolute odometry along a log, from either layout.
/// Actions layout: integrates CActionRobotMovement2D::rawOdometryIncrementReading of each
/// action's best movement estimation (starting at the origin). Observations layout: takes the
/// absolute pose of each CObservationOdometry. Unknown (nullopt) until the first of either.
class OdometryTracker {
  public:
    /// A non-finite increment is not integrated (the sum stays finite): the pose of that one
    /// entry is NaN, which kfd::checkScan turns into "unknown" and counts.
    void onAction(const mrpt::obs::CActionCollection& actions);
    /// Only CObservationOdometry changes the pose; other observations are ignored.
    void onObservation(const mrpt::obs::CObservation& obs);
    const std::optional<Pose2D>& current() const { return current_; }

  private:
    mrpt::poses::CPose2D accum_;  // integrated increments (actions layout)
    std::optional<Pose2D> current_;
};

/// A message of a foreign log that has no MRPT form of its own (another topic of a ROS bag), or
/// the original message behind a scan converted from one: what a bag writer copies. Opaque
/// outside the bag layer (defined in libkfd/src/io/bag_message.h).
struct NativeMessage;

/// One step of a log, in file order. Exactly one of the kinds below; the pointers of the other
/// kinds are null. Consumers may modify the objects (e.g. erase scans from `frame`).
struct SourceEntry {
    enum class Kind {
        Observation,  // one observation on its own (observations layout): `observation`
        Frame,        // a sensory frame: `frame`, with `action` = the odometry action read just
                      // before it (actions layout), or null when the frame has none
        Action,       // an odometry action not followed by a sensory frame: `action`
        Other,        // any other object (a map, a comment...), to be copied as it is: `other`
        Native,       // a message with no MRPT form (another topic of a bag): `native` only;
                      // rawlog outputs leave it out, a bag output copies it
    };
    Kind kind = Kind::Other;
    mrpt::obs::CObservation::Ptr observation;
    mrpt::obs::CActionCollection::Ptr action;
    mrpt::obs::CSensoryFrame::Ptr frame;
    mrpt::serialization::CSerializable::Ptr other;
    /// The original message of a bag: set for Native entries and for the scans converted from a
    /// bag's LaserScan messages (null otherwise, e.g. for the odometry a bag source derives).
    std::shared_ptr<const NativeMessage> native;
    /// The tracker's odometry once this entry is read (its action or odometry observation
    /// applied): the odometry of the entry's scans.
    std::optional<Pose2D> odometry;
    std::size_t index = 0;         // 0-based number of the entry
    std::size_t objects_read = 0;  // objects of the file read so far, this entry's included

    /// Calls fn(const mrpt::serialization::CSerializable::Ptr&) for each of the entry's file
    /// objects in file order (action then frame, or the single object).
    template <class Fn>
    void forEachObject(Fn&& fn) const {
        switch (kind) {
            case Kind::Observation:
                fn(mrpt::serialization::CSerializable::Ptr(observation));
                break;
            case Kind::Frame:
                if (action) fn(mrpt::serialization::CSerializable::Ptr(action));
                fn(mrpt::serialization::CSerializable::Ptr(frame));
                break;
            case Kind::Action:
                fn(mrpt::serialization::CSerializable::Ptr(action));
                break;
            case Kind::Other:
                fn(other);
                break;
            case Kind::Native:  // no MRPT object
                break;
        }
    }

    /// Calls fn(const mrpt::obs::CObservation2DRangeScan::Ptr&) for each 2D range scan of the
    /// entry: the observation itself, or every scan of the frame, in order.
    template <class Fn>
    void forEachScan(Fn&& fn) const {
        using Scan2D = mrpt::obs::CObservation2DRangeScan;
        if (kind == Kind::Observation) {
            if (auto s = std::dynamic_pointer_cast<Scan2D>(observation)) fn(s);
        } else if (kind == Kind::Frame) {
            for (const auto& o : *frame)
                if (auto s = std::dynamic_pointer_cast<Scan2D>(o)) fn(s);
        }
    }
};

/// What a source repaired or left out while reading a log, counted: the summaries (kfd-filter's,
/// kfd-icp-slam's summary.json) report what is not 0. An MRPT rawlog has none of these.
struct SourceCounters {
    /// CARMEN: lines that are not CARMEN lines (a control character or a byte above 127 outside
    /// a comment, or a first field that is not an upper-case keyword such as FLASER: binary data,
    /// another format), skipped. A log where they outweigh the other lines in bytes is refused
    /// (CarmenError, at its end).
    std::size_t lines_unparsable = 0;
    std::uint64_t bytes_unparsable = 0;     // their bytes, line ends included
    std::size_t first_unparsable_line = 0;  // the first one's number (1-based); 0: none
    /// Bags: LaserScan messages whose angle fields do not match their beam count (not finite,
    /// an increment of 0 or of the wrong sign, (angle_max - angle_min) / angle_increment more
    /// than one beam away from n - 1): their aperture is made NaN, so the door skips them as
    /// bad_aperture.
    std::size_t scans_bad_angles = 0;
    /// Bags: LaserScan, Odometry and /tf odometry messages whose header stamp is 0 (unset): their
    /// bag record time is used instead.
    std::size_t stamps_zero = 0;
    /// Bags with odometry: scans stamped more than BagSource's hold time (1 s) before the first
    /// odometry sample or after the last one (or than the source can look ahead): their odometry
    /// is unknown, not the nearest sample.
    std::size_t scans_without_odometry = 0;

    bool any() const {
        return lines_unparsable || scans_bad_angles || stamps_zero || scans_without_odometry;
    }
};

/// A log read entry by entry, never loaded whole. Implementations: RawlogSource (MRPT
/// rawlogs, kfd/io/rawlog_source.h), BagSource (ROS 1 bags, kfd/io/bag_source.h),
/// CarmenSource (CARMEN logs, kfd/io/carmen_source.h); openSource
/// (kfd/io/open_source.h) picks one by the log's content.
class Source {
  public:
    virtual ~Source() = default;
    /// Reads the next entry into `e` (every field overwritten). Returns false at a clean end of
    /// the log; throws SourceError (or a subclass) when it cannot be read, is truncated or is
    /// corrupt.
    virtual bool next(SourceEntry& e) = 0;
    /// The log's path, for messages.
    virtual const std::string& path() const = 0;
    /// Progress: position in the decoded input stream and its total size (bytes; for a
    /// compressed file the decoded size).
    virtual std::uint64_t bytesRead() const = 0;
    virtual std::uint64_t bytesTotal() const = 0;
    /// What the source repaired or left out so far (final once next() returned false).
    virtual SourceCounters counters() const { return {}; }
};

/// The formats kfd reads.
enum class LogFormat {
    Rawlog,
    Bag,  // ROS 1 bag
    Carmen,
    Rosbag2,  // ROS 2 rosbag2: a folder with metadata.yaml, or one sqlite3 .db3
    Mcap,     // an MCAP file (ROS 2's default bag format from Iron on)
};
const char* toString(LogFormat f);

/// What a source reads from a log whose streams are named (a bag's topics and frames). Empty
/// fields are chosen automatically (BagSource documents the rules); rawlogs and CARMEN logs
/// ignore them.
struct SourceOptions {
    std::string scan_topic;  // a sensor_msgs/LaserScan topic; auto: the only one, else /scan
    std::string odom_topic;  // a nav_msgs/Odometry topic, "tf" (odom -> base from /tf) or
                             // "none" (laser only); auto: the only Odometry topic (else
                             // /odom), else /tf when it holds odom -> base, else none
    std::string odom_frame;  // tf: the odometry frame; auto: "odom"
    std::string base_frame;  // the robot frame; auto: the Odometry's child_frame_id, else the
                             // child of odom in /tf, else "base_link"
};

}  // namespace kfd
