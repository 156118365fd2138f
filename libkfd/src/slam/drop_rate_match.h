// kfd-icp-slam's matched drop rates (--match-drop, --match-drop-of): the drop rate to match
// (given, or measured by a pre-pass of another mode's pre-filter, no ICP), then the odometry
// motion filter's thresholds (a bisection) or the decimation's share that reach it. Internal to
// kfd_slam.
#pragma once

#include "kfd/pipeline/pipeline.h"
#include "kfd/slam/icp_slam_runner.h"

namespace kfd::icp_slam {

/// Odometry and decimate modes with a target: sets sum.target_drop_pct, sum.cpu_s_match (the
/// pre-pass of --match-drop-of) and the matched stage's parameters in sum.pipeline. SlamError
/// when the target is outside [0, 100).
void matchDropRate(const IcpSlamOptions& opts, const Pipeline::Params& kfd_params,
                   IcpSlamSummary& sum);

}  // namespace kfd::icp_slam
