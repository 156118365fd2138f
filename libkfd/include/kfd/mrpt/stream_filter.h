// The one door for a scan: every driver (kfd-filter, kfd-icp-slam and its pre-pass, kfd-render,
// the simulator's tools, a live node) gives its scans to StreamFilter::process, one call per
// scan, state kept per sensor.
#pragma once

#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <mrpt/obs/CObservation2DRangeScan.h>

#include "kfd/io/source.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/scan_record.h"
#include "kfd/pipeline/pipeline.h"

namespace kfd {

/// What StreamFilter::process() decided for one scan.
struct StreamResult {
    bool keep = false;  // a keyframe: the scan goes on; false: dropped or skipped
    /// Kept, but not finished: a stage waits for the sensor's next scan (the denoise stage's
    /// next_scan). Its report and record are incomplete and its removals not yet applied; the
    /// door hands it back finished from takeFinished() (see StreamFilter).
    bool pending = false;
    /// The observation this result is about (as given to process()).
    mrpt::obs::CObservation2DRangeScan* scan = nullptr;
    /// Not None: the scan's geometry is unusable (kfd/mrpt/scan_check.h); no stage ran and the
    /// scan is unchanged but for its bad ranges. Callers leave it out like a dropped scan.
    ScanSkipReason skipped = ScanSkipReason::None;
    bool geometry_reset = false;   // this sensor's geometry changed: its state was reset first
    std::size_t bad_ranges = 0;    // beams marked invalid by the check (NaN, inf, < 0, huge)
    bool bad_odometry = false;     // the odometry given was not finite: used as unknown
    bool stamp_backwards = false;  // this scan's stamp is before the sensor's previous one
    ScanReport report;             // every stage's diagnostics and the time spent
    ScanRecord record;             // the scan's row of the per-scan CSV (kfd/io/scan_csv.h)
};

/// Holds the state of a scan stream: one Pipeline per sensor label, so two lasers on one robot
/// never share a keyframe window. Call process() for each scan in time order, e.g. from a SLAM
/// front end:
///
///     kfd::StreamFilter kfd(kfd::loadConfigFile("share/kfd/default.ini"));
///     auto r = kfd.process(*scan, odometryPose);  // checks and cleans `scan` in place
///     if (r.keep) slam.processScan(scan);
///
/// When a sensor's geometry (beam count, aperture or direction, as its stages see it: after a
/// beam_count stage's resampling) changes, its state is reset
/// and the scan is treated as the first of a new stream (StreamResult::geometry_reset).
///
/// One scan of latency (the denoise key next_scan = true): a kept scan may come back pending
/// (StreamResult::pending): the caller keeps that observation alive and unchanged, and holds
/// what it would output after it (to keep its output in order), until the door finishes it:
/// during the sensor's next process() call, or finish() at the end of a log, reset(), or a
/// geometry change. Finished scans (their removals now marked in the observation, their final
/// report and record) are taken in order with takeFinished() after each of those calls:
///
///     auto r = kfd.process(*scan, odometryPose);
///     StreamResult done;
///     while (kfd.takeFinished(done)) slam.processScan(*done.scan);  // earlier scans first
///     if (r.keep && !r.pending) slam.processScan(*scan);
///     ...
///     kfd.finish();  // the end: then takeFinished() as above
///
/// Without it nothing is ever pending and takeFinished() returns false. The counters count a
/// pending scan once it is finished.
///
/// **The door holds the delay** (issue 34): a driver that gives each scan a `done` callback
/// and queues its other output with then() never sees a pending scan. Every scan's finished
/// result and every then() run in input order, at once when nothing is held before them:
///
///     kfd.process(*scan, odometryPose, [&slam, scan](kfd::StreamResult& r) {
///         if (r.keep) slam.processScan(*scan);  // finished: removals marked, record final
///     });
///     kfd.then([&] { writer.write(odometryEntry); });  // after that scan, in input order
///     ...
///     kfd.finish();  // the end of the stream: whatever is held is finished and handed back
class StreamFilter {
  public:
    /// Builds stages for a new sensor; lets callers add custom stages (e.g. baselines).
    using StageFactory = std::function<void(Pipeline&)>;

    /// `params`: kfd's defaults (kfdDefaults(), share/kfd/default.ini) unless given, so that a
    /// default-constructed filter runs what kfd-filter runs without -c (pass Pipeline::Params{}
    /// for the stages' own Params defaults: distance, keyframe, denoise without the odometry
    /// check). `one_scan_latency`: the caller handles pending results (takeFinished(),
    /// finish()). Without it, a pipeline that holds scans (the denoise key next_scan = true) is
    /// refused: kfd::ParameterError naming next_scan (a tool that would use a held scan
    /// unfinished).
    explicit StreamFilter(const Pipeline::Params& params = kfdDefaults(), StageFactory extra = {},
                          bool one_scan_latency = false);

    /// The one door: checks the scan (kfd::checkScan, the only place it runs), then runs the
    /// pipeline. A scan with a bad geometry is skipped (StreamResult::skipped says why; nothing
    /// runs, nothing is thrown); bad ranges are marked invalid and non-finite odometry becomes
    /// unknown, and the scan goes on. Noise and out-of-range beams are marked invalid in place
    /// (ranges, beam count and angles are kept). `odometry` (absolute, robot frame) feeds the
    /// motion guards. Every call fills the result's record and adds to counters().
    StreamResult process(mrpt::obs::CObservation2DRangeScan& scan,
                         const std::optional<Pose2D>& odometry = std::nullopt);

    /// What a driver does with a scan's finished result (called once, in input order).
    using OnFinished = std::function<void(StreamResult&)>;
    /// process(), handing the scan's result to `done` once finished: at once, or, when a
    /// stage waits for the sensor's next scan (next_scan), when that scan, finish(), reset()
    /// or a geometry change finishes it; never before anything given earlier (a later scan's
    /// `done` and every then() wait behind a held scan). The observation must stay alive and
    /// unchanged until `done` ran (capture its shared pointer). Returns the result as known
    /// now (`keep` is final; the record and removals of a held scan are not).
    StreamResult process(mrpt::obs::CObservation2DRangeScan& scan,
                         const std::optional<Pose2D>& odometry, OnFinished done);
    /// Runs `fn` in input order: at once when no scan is held, else after the held scans'
    /// `done` calls (a driver's output that must follow them, e.g. the next log entry).
    void then(std::function<void()> fn);

    /// What every call so far added up to (the figures of kfd-filter's and kfd-icp-slam's
    /// summaries).
    const ScanCounters& counters() const { return counters_; }
    /// The listed stages' declared outputs: the per-scan CSV's stage columns (ScanCsvWriter),
    /// a record's cell by name (`outputs().cell(record.report, "corridor")`).
    const StageOutputs& outputs() const { return outputs_; }

    /// Laser only: the odometry given to process() is ignored (kfd decides from the scans
    /// alone; what --laser-only sets in every tool that reads logs).
    void setLaserOnly(bool on) { laser_only_ = on; }
    bool laserOnly() const { return laser_only_; }

    /// The next finished scan that was pending, in the order they were finished (with several
    /// sensors that may differ from the input order: record.index has it); false when none.
    bool takeFinished(StreamResult& out);
    /// Finishes every sensor's pending scan without a next scan (the end of a log); the `done`
    /// and then() calls waiting behind them run.
    void finish();
    /// Scans pending now (returned pending, not yet finished).
    std::size_t pendingCount() const;

    /// Forgets every sensor (the counters stay); pending scans are finished first.
    void reset() {
        finish();
        sensors_.clear();
    }
    std::size_t sensorCount() const { return sensors_.size(); }
    /// At most this many sensors keep state (a pipeline each, ~30-60 KB): a scan of a new
    /// sensor beyond it evicts the sensor seen least recently, its held scan finished first
    /// (counted: ScanCounters::sensors_evicted). A stream of ever new sensor labels or frame
    /// ids then holds bounded memory. kDefaultMaxSensors unless set; at least 1.
    static constexpr std::size_t kDefaultMaxSensors = 64;
    void setMaxSensors(std::size_t n) { max_sensors_ = n < 1 ? 1 : n; }
    std::size_t maxSensors() const { return max_sensors_; }
    const Pipeline::Params& params() const { return params_; }
    /// The clusters of the last denoised scan of a sensor (nullptr if none).
    const Clusters* lastClusters(const std::string& sensor_label) const;

  private:
    struct Sensor {
        std::unique_ptr<Pipeline> pipeline;
        ScanGeometry geometry;
        Scan scan;  // reused buffer
        double last_stamp = std::numeric_limits<double>::quiet_NaN();
        StreamResult held;            // the pending scan's result (held.scan: its observation)
        std::uint64_t last_used = 0;  // the door's scan count when it last had a scan
    };
    // Evicts the sensor seen least recently (its held scan finished and recorded first).
    void evictOldest();
    Sensor& sensorFor(const std::string& label);
    void record(StreamResult& r);
    void count(const StreamResult& r);
    // The sensor's pending scan, when its pipeline finished it: marks its removals in the
    // observation, records it and queues it for takeFinished().
    void collectFinished(Sensor& s);

    // One entry per process(.., done) and then() call, in input order; the front ones run as
    // soon as they are no longer held (drain()).
    struct InOrder {
        const mrpt::obs::CObservation2DRangeScan* scan = nullptr;  // held: the scan it waits for
        bool held = false;
        StreamResult result;
        OnFinished done;
        std::function<void()> fn;
    };
    std::deque<InOrder> in_order_;
    void drain();

    Pipeline::Params params_;
    StageFactory extra_;
    std::unique_ptr<Pipeline> spare_;  // built (and validated) by the constructor
    std::map<std::string, Sensor> sensors_;
    Scan spare_scan_;                    // the next scan's buffer (swapped with its sensor's)
    std::deque<StreamResult> finished_;  // finished pending scans, oldest first
    ScanCounters counters_;
    StageOutputs outputs_;  // of params_.stages
    bool laser_only_ = false;
    std::size_t max_sensors_ = kDefaultMaxSensors;
};

/// Empty when a run through the door had a usable scan (one that reached the pipeline); else
/// what the run's error says, naming the log: "no laser scan in LOG" when the door saw none,
/// "no usable scan in LOG: all N scans skipped (bad_aperture N: an aperture that is not finite,
/// <= 0 or above 2 pi)" when it skipped every one (with the source's count of LaserScans
/// whose angle fields do not match their beam count, when there are some). RawlogFilter and
/// IcpSlamRunner throw it: a run with no usable scan writes nothing and fails.
/// The summary lines on why scans were kept or dropped (every reason with its count and what it
/// means, most frequent first: "reasons  covered   2953  dropped: the view has not moved ...")
/// and on the kept scans the denoisers cut most ("most removed ... scan 812 22.8 % (82 of
/// 359); ..."), without indentation. kfd-filter and kfd-icp-slam print them alike.
std::vector<std::string> reasonLines(const ScanCounters& counters);

std::string noUsableScan(const ScanCounters& counters, const SourceCounters& source,
                         const std::string& log);

}  // namespace kfd
