#include "drop_rate_match.h"

#include <mrpt/obs/CObservation2DRangeScan.h>

#include <algorithm>
#include <ctime>
#include <optional>
#include <vector>

#include "icp_slam_steps.h"
#include "kfd/baselines/decimate_stage.h"
#include "kfd/baselines/motion_stage.h"
#include "kfd/mrpt/scan_check.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/slam/prefilter_modes.h"

namespace kfd::icp_slam {
namespace {

using mrpt::obs::CObservation2DRangeScan;

struct ScanStamp {
    double t;
    std::optional<Pose2D> odometry;
};

// Timestamps and odometry of every scan after the skipped start (for matching the odometry
// baseline's drop rate to a target before the real run); a non-finite odometry is unknown
// (kfd::checkOdometry, the door's rule).
std::vector<ScanStamp> scanOdometry(const std::string& rawlog, const SourceOptions& options,
                                    std::size_t skip_scans, bool laser_only) {
    std::vector<ScanStamp> out;
    forEachRunScan(rawlog, options, skip_scans,
                   [&](const CObservation2DRangeScan::Ptr& scan, std::optional<Pose2D> odo) {
                       if (laser_only) odo.reset();
                       checkOdometry(odo);
                       out.push_back({stampOf(*scan), odo});
                   });
    return out;
}

// The drop rate (%) of a pre-filter over the log, as the real run would see it (the same
// skipped start, the same door, odometry or none): the pre-filter alone, no ICP. The door keeps
// each scan alive until it is finished (the callback holds it); the counters are complete
// after finish().
double pipelineDropPct(const std::string& rawlog, const SourceOptions& options,
                       const Pipeline::Params& pipeline, std::size_t skip_scans, bool laser_only) {
    StreamFilter filter(pipeline, {}, /*one_scan_latency=*/true);
    filter.setLaserOnly(laser_only);
    forEachRunScan(rawlog, options, skip_scans,
                   [&](const CObservation2DRangeScan::Ptr& scan, std::optional<Pose2D> odo) {
                       filter.process(*scan, odo, [scan](StreamResult&) {});
                   });
    filter.finish();
    return filter.counters().notKeptPercent();
}

double dropPct(const std::vector<ScanStamp>& scans, const MotionFilter::Params& p) {
    MotionFilter f(p);
    std::size_t dropped = 0;
    for (const auto& s : scans) dropped += f.keep(s.t, s.odometry) ? 0 : 1;
    return scans.empty() ? 0.0 : 100.0 * static_cast<double>(dropped) / scans.size();
}

// Bisection on D (angle = 30 deg per metre of D): the drop rate grows with D.
MotionFilter::Params motionParamsForDropRate(const std::vector<ScanStamp>& scans,
                                             double target_pct) {
    MotionFilter::Params p;
    p.max_interval_s = 0.0;
    double lo = 0.0, hi = 5.0;
    for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        p.max_distance_m = mid;
        p.max_angle_deg = 30.0 * mid;
        if (dropPct(scans, p) < target_pct)
            lo = mid;
        else
            hi = mid;
    }
    p.max_distance_m = hi;
    p.max_angle_deg = 30.0 * hi;
    return p;
}

}  // namespace

// Odometry and decimate modes with a target: the drop rate to match (given, or measured by a
// pre-pass of another mode's pre-filter), then the thresholds or share that reach it.
void matchDropRate(const IcpSlamOptions& opts, const Pipeline::Params& kfd_params,
                   IcpSlamSummary& sum) {
    if (opts.match_drop_of) {
        const std::clock_t m0 = std::clock();
        sum.target_drop_pct = pipelineDropPct(sum.rawlog, opts.source,
                                              pipelineForMode(*opts.match_drop_of, kfd_params),
                                              opts.skip_scans, opts.laser_only);
        sum.cpu_s_match = static_cast<double>(std::clock() - m0) / CLOCKS_PER_SEC;
    } else if (opts.odometry_target_drop_pct) {
        sum.target_drop_pct = *opts.odometry_target_drop_pct;
    }
    if (!sum.target_drop_pct) return;
    const double target = *sum.target_drop_pct;
    if (!(target >= 0.0 && target < 100.0))
        throw SlamError("the target drop rate must be in [0, 100)");
    if (opts.mode == PrefilterMode::Odometry)
        sum.pipeline.get<MotionStage>() = motionParamsForDropRate(
            scanOdometry(sum.rawlog, opts.source, opts.skip_scans, opts.laser_only), target);
    else
        sum.pipeline.get<DecimateStage>().keep_fraction = 1.0 - target / 100.0;
}

}  // namespace kfd::icp_slam
