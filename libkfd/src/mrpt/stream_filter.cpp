#include "kfd/mrpt/stream_filter.h"

#include <cmath>
#include <stdexcept>

#include "kfd/mrpt/default_stages.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/mrpt/scan_check.h"

namespace kfd {

StreamFilter::StreamFilter(const Pipeline::Params& params, StageFactory extra)
    : params_(params), extra_(std::move(extra)) {
    // Validated now, not at the first scan; the first sensor takes this pipeline.
    spare_ = std::make_unique<Pipeline>(params_, defaultStageRegistry());
}

StreamFilter::Sensor& StreamFilter::sensorFor(const std::string& label) {
    auto it = sensors_.find(label);
    if (it != sensors_.end()) return it->second;
    Sensor s;
    s.pipeline =
        spare_ ? std::move(spare_) : std::make_unique<Pipeline>(params_, defaultStageRegistry());
    if (extra_) extra_(*s.pipeline);
    return sensors_.emplace(label, std::move(s)).first->second;
}

StreamResult StreamFilter::process(mrpt::obs::CObservation2DRangeScan& obs,
                                   const std::optional<Pose2D>& odometry) {
    std::optional<Pose2D> odo = odometry;
    const ScanCheck check = checkScan(obs, &odo);
    if (!check.ok())
        throw ScanError(std::string("scan rejected: ") + toString(check.reject), "scan");
    StreamResult res;
    res.bad_ranges = check.bad_ranges;
    res.bad_odometry = check.bad_odometry;
    res.sensor_label = obs.sensorLabel;
    Sensor& s = sensorFor(obs.sensorLabel);
    const ScanGeometry g = geometryOf(obs);
    if (s.geometry.beams != 0 && g != s.geometry) {
        s.pipeline->reset();
        res.geometry_reset = true;
    }
    s.geometry = g;
    toCore(obs, s.scan);
    s.scan.odometry = odo;
    if (std::isfinite(s.scan.timestamp)) {
        res.stamp_backwards = std::isfinite(s.last_stamp) && s.scan.timestamp < s.last_stamp;
        s.last_stamp = s.scan.timestamp;
    }
    res.report = s.pipeline->process(s.scan);
    res.keep = res.report.keep;
    applyValidity(s.scan, obs);
    return res;
}

const Clusters* StreamFilter::lastClusters(const std::string& sensor_label) const {
    const auto it = sensors_.find(sensor_label);
    return it == sensors_.end() ? nullptr : it->second.pipeline->lastClusters();
}

}  // namespace kfd
