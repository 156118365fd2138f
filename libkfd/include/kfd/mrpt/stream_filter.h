// The streaming API: one call per scan, state kept per sensor.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include <mrpt/obs/CObservation2DRangeScan.h>

#include "kfd/core/pipeline.h"

namespace kfd {

/// What StreamFilter::process() decided for one scan.
struct StreamResult {
    bool keep = true;             // false: not a keyframe, drop the scan
    bool geometry_reset = false;  // this sensor's geometry changed: its state was reset first
    std::string sensor_label;
    std::size_t bad_ranges = 0;    // beams marked invalid by checkScan (NaN, inf, < 0, huge)
    bool bad_odometry = false;     // the odometry given was not finite: used as unknown
    bool stamp_backwards = false;  // this scan's stamp is before the sensor's previous one
    ScanReport report;             // every stage's diagnostics and the time spent
};

/// Holds the state of a scan stream: one Pipeline per sensor label, so two lasers on one robot
/// never share a keyframe window. Call process() for each scan in time order, e.g. from a SLAM
/// front end:
///
///     kfd::StreamFilter kfd(kfd::loadConfigFile("share/kfd/default.ini"));
///     auto r = kfd.process(*scan, odometryPose);  // cleans `scan` in place
///     if (r.keep) slam.processScan(scan);
///
/// When a sensor's geometry (beam count, aperture or direction) changes, its state is reset
/// and the scan is treated as the first of a new stream (StreamResult::geometry_reset).
class StreamFilter {
  public:
    /// Builds stages for a new sensor; lets callers add custom stages (e.g. baselines).
    using StageFactory = std::function<void(Pipeline&)>;

    explicit StreamFilter(const Pipeline::Params& params = {}, StageFactory extra = {});

    /// Runs the pipeline on `scan`. Noise and out-of-range beams are marked invalid in place
    /// (ranges, beam count and angles are kept). `odometry` (absolute, robot frame) feeds the
    /// motion guards. The scan is first checked by kfd::checkScan (kfd/mrpt/scan_check.h): bad
    /// ranges become invalid, non-finite odometry becomes unknown, and a scan with a bad
    /// geometry (beam count, aperture) throws kfd::ScanError before any stage runs — callers
    /// that skip such scans call checkScan themselves first (RawlogFilter, IcpSlamRunner).
    StreamResult process(mrpt::obs::CObservation2DRangeScan& scan,
                         const std::optional<Pose2D>& odometry = std::nullopt);

    /// Forgets every sensor.
    void reset() { sensors_.clear(); }
    std::size_t sensorCount() const { return sensors_.size(); }
    const Pipeline::Params& params() const { return params_; }
    /// The clusters of the last denoised scan of a sensor (nullptr if none).
    const Clusters* lastClusters(const std::string& sensor_label) const;

  private:
    struct Sensor {
        std::unique_ptr<Pipeline> pipeline;
        ScanGeometry geometry;
        Scan scan;  // reused buffer
        double last_stamp = std::numeric_limits<double>::quiet_NaN();
    };
    Sensor& sensorFor(const std::string& label);

    Pipeline::Params params_;
    StageFactory extra_;
    std::unique_ptr<Pipeline> spare_;  // built (and validated) by the constructor
    std::map<std::string, Sensor> sensors_;
};

}  // namespace kfd
