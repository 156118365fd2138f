// The input layer: a sensor log read entry by entry, whatever its file format.
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

#include "kfd/core/error.h"
#include "kfd/core/scan.h"

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

/// One step of a log, in file order. Exactly one of the kinds below; the pointers of the other
/// kinds are null. Consumers may modify the objects (e.g. erase scans from `frame`).
struct SourceEntry {
    enum class Kind {
        Observation,  // one observation on its own (observations layout): `observation`
        Frame,        // a sensory frame: `frame`, with `action` = the odometry action read just
                      // before it (actions layout), or null when the frame has none
        Action,       // an odometry action not followed by a sensory frame: `action`
        Other,        // any other object (a map, a comment...), to be copied as it is: `other`
    };
    Kind kind = Kind::Other;
    mrpt::obs::CObservation::Ptr observation;
    mrpt::obs::CActionCollection::Ptr action;
    mrpt::obs::CSensoryFrame::Ptr frame;
    mrpt::serialization::CSerializable::Ptr other;
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

/// A log read entry by entry, never loaded whole. Implementations: RawlogSource (MRPT
/// rawlogs); ROS bags and CARMEN logs come next, behind this same interface.
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
};

/// Opens the log at `path` with the source for its format (today every file is read as an
/// MRPT rawlog, plain or gzip). Throws SourceError when it cannot be opened.
std::unique_ptr<Source> openSource(const std::string& path);

}  // namespace kfd
