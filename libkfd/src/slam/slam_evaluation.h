// kfd-icp-slam's evaluation: the run's trajectory against the ground truth (ATE) and the
// relations (all, local and long apart). Internal to kfd_slam.
#pragma once

#include <vector>

#include "kfd/eval/relations.h"
#include "kfd/eval/trajectory.h"
#include "kfd/slam/icp_slam_runner.h"

namespace kfd::icp_slam {

/// ATE against `ground_truth` (when opts names one) and the relations error, all and split at
/// opts.split_seconds into local and long (a subset that is empty or matched nothing stays
/// absent), into sum. EvalError when no relation matched (never a perfect 0.0).
void evaluateTrajectory(const IcpSlamOptions& opts, const std::vector<Relation>& relations,
                        const Trajectory& trajectory, const Trajectory& ground_truth,
                        IcpSlamSummary& sum);

}  // namespace kfd::icp_slam
