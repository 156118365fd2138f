// The live side of the one door: LaserScan messages as a robot or `rosbag play` delivers them,
// each through kfd::StreamFilter::process, with the rules a live stream needs (time jumping
// back, scans out of order, several lasers). No communication: the ROS 1 node
// (kfd::ros1::ScanFilterNode) and the ROS 2 node (kfd::ros2::Ros2Node) wire it to their topics, so
// both transports make the same decisions; tests drive it with hand-made messages.
#pragma once

#include <sensor_msgs/LaserScan.h>

#include <cstddef>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "kfd/io/bag_writer.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/pipeline/pipeline.h"

namespace kfd::live {

/// The node's counters (its ~stats and /diagnostics keys).
struct LiveCounters {
    std::size_t scans_in = 0;         // every LaserScan received
    std::size_t scans_kept = 0;       // published on scan_filtered (a held one once finished)
    std::size_t points_removed = 0;   // beams marked NaN/+Inf in the published scans
    std::size_t out_of_order = 0;     // dropped: older than the last scan of its frame
    std::size_t odom_missing = 0;     // scans filtered laser-only: no odometry at their stamp
    std::size_t resets = 0;           // state forgotten: time jumped back
    std::size_t geometry_resets = 0;  // a frame's beam count or angles changed (the door's reset)
    std::size_t scans_skipped = 0;    // unusable geometry (the door's check): not published
    /// Dropped before the door: a stamp kfd cannot compute with (not finite, negative, or
    /// within kStampMargin of the end of ROS 1's 32-bit time), or a message whose handling
    /// threw (the node catches it per message).
    std::size_t stamps_unusable = 0;
    std::size_t callback_errors = 0;
    /// Frames whose state was dropped to keep at most StreamFilter::kDefaultMaxSensors (the
    /// least recently heard first, a held keyframe published first): a flood of frame ids.
    std::size_t sensors_evicted = 0;
    /// Scans that never arrived: gaps in a frame's header.seq (ROS 1; lost in the subscriber
    /// queue while a scan waited, or before the node).
    std::size_t scans_missing = 0;
};

/// What in `c` a user should look at, in words ("12 scans missing (gaps in header.seq)", ...),
/// empty when nothing: the node's diagnostics go to WARN with it. `odom_expected`: the node has
/// an odometry source, so scans without it count.
std::vector<std::string> attention(const LiveCounters& c, bool odom_expected);

/// s: stamps this close to the end of ROS 1's time (2^32 s) are unusable: the waits and
/// windows added to a stamp (tf_wait, the odometry's hold) must stay inside it.
constexpr double kStampMargin = 86400.0;
/// A stamp (s) kfd computes with: finite, >= 0 and at most 2^32 - 1 - kStampMargin.
bool usableStamp(double seconds);

/// What LiveFilter::process decided for one message.
struct LiveResult {
    bool publish = false;  // a keyframe: publish the marked message
    /// A keyframe held for the frame's next scan (the denoise key next_scan): not published
    /// now; LiveFilter keeps a copy and hands it out finished from takeReady().
    bool pending = false;
    bool reset = false;         // time jumped back: every frame's state was forgotten first
    bool out_of_order = false;  // dropped without reaching the door
    std::size_t removed = 0;    // beams marked in the message
    StreamResult stream;        // the door's result (default when out_of_order)
};

class LiveFilter {
  public:
    struct Params {
        Pipeline::Params pipeline;               // kfd's configuration
        RemovedMark removed = RemovedMark::NaN;  // how removed beams are marked (REP 117)
        /// s: a scan this much (or more) older than the last scan of its frame means time
        /// jumped back (a bag looping, a simulator restarting): every frame's state is reset
        /// and the scan goes on as the first of a new stream. A scan older by less is out of
        /// order and dropped.
        double reset_jump = 1.0;
        /// Frames whose state is kept at most (StreamFilter::setMaxSensors): a new frame beyond
        /// it evicts the one heard from longest ago (its held keyframe finished first).
        std::size_t max_sensors = StreamFilter::kDefaultMaxSensors;
    };

    explicit LiveFilter(const Params& p);

    /// One received scan: `m` is marked in place (removed beams) and is what to publish when
    /// the result says so. `stamp`: the scan's time (s; its header's, or the receive time
    /// when that is 0). `odometry`: the robot's pose at that stamp, nothing when unknown
    /// (`odom_expected`: the node has an odometry source, so unknown counts odom_missing).
    /// `mount`: the laser in the robot's base frame.
    ///
    /// One scan of latency (next_scan = true): a keyframe comes back `pending` and is finished
    /// by its frame's next scan (or a reset, a geometry change, finish()). Finished messages,
    /// marked, wait in order for takeReady(): after each call of process(), onClock(), reset()
    /// and finish(), publish what takeReady() gives first, then the call's own `publish`:
    ///
    ///     const auto r = live.process(m, stamp, odom, expected);
    ///     for (sensor_msgs::LaserScan::Ptr done; live.takeReady(done);) pub.publish(done);
    ///     if (r.publish) pub.publish(m);
    ///
    /// Without next_scan nothing is ever pending and takeReady() returns false.
    LiveResult process(sensor_msgs::LaserScan& m, double stamp,
                       const std::optional<Pose2D>& odometry, bool odom_expected,
                       const Pose2D& mount = Pose2D{0.0, 0.0, 0.0});

    /// The ROS clock (s) when a scan arrives, with simulated time (/clock, `rosbag play
    /// --clock`): a clock that went back (the bag looping or restarting, however short) resets
    /// every frame's state and counts a reset, before the scan's own rules. True when it did.
    bool onClock(double now);
    /// A received scan whose stamp is not usableStamp(): counted (scans_in, stamps_unusable),
    /// never reaches the door; false. True for a usable stamp (nothing counted: process()
    /// counts the scan).
    bool acceptStamp(double stamp);
    /// A received message whose handling threw: counted (scans_in when `scan`,
    /// callback_errors).
    void countError(bool scan);
    /// `n` scans of a frame never arrived (a gap in its header.seq): counted scans_missing.
    void countMissing(std::size_t n) { counters_.scans_missing += n; }
    /// Forgets every frame's state (the counters stay); what a time jump does. A held keyframe
    /// is finished first (takeReady()).
    void reset();
    /// Finishes every held keyframe without its next scan (the node shutting down).
    void finish();
    /// The next finished keyframe to publish, oldest first; false when none.
    bool takeReady(sensor_msgs::LaserScan::Ptr& out);
    /// Keyframes held now, waiting for their next scan.
    std::size_t heldCount() const { return door_.pendingCount(); }
    const LiveCounters& counters() const { return counters_; }
    const StreamFilter& door() const { return door_; }
    const Params& params() const { return params_; }

  private:
    // One message through the door: whether the door finished it during process() (then the
    // caller's message is marked), else the copy the door's callback marks and queues for
    // takeReady() once finished.
    struct Delivery {
        bool finished = false, keep = false;
        sensor_msgs::LaserScan::Ptr copy;
    };
    // Marks a kept scan's removals in its message and counts it; the beams marked.
    std::size_t markKept(sensor_msgs::LaserScan& m, const mrpt::obs::CObservation2DRangeScan& o);

    Params params_;
    StreamFilter door_;
    std::deque<sensor_msgs::LaserScan::Ptr> ready_;  // finished, to publish, oldest first
    std::map<std::string, double> last_stamp_;       // per frame_id
    double last_clock_ = -1.0;                       // onClock's last time (< 0: none yet)
    LiveCounters counters_;
};

/// The counters as the nodes' diagnostics name them, in order: scans_in, scans_kept,
/// dropped_pct (% of scans_in not kept), points_removed, out_of_order, odom_missing, resets,
/// geometry_resets, scans_skipped.
std::vector<std::pair<std::string, double>> counterValues(const LiveCounters& c);

/// The sensor label of a frame_id: without its leading '/' (as the bag source labels a topic).
std::string frameLabel(const std::string& frame_id);

}  // namespace kfd::live
