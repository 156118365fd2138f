// The stage registry the tools use: the paper's stages, the laser_filters-style filters, then
// the baselines.
#pragma once

#include "kfd/baselines/stages.h"
#include "kfd/filters/stages.h"
#include "kfd/pipeline/stage_registry.h"

namespace kfd {

/// registerCoreStages(), registerFilterStages(), then registerBaselineStages(): distance,
/// keyframe, denoise, ..., angle_bounds, footprint, intensity, motion, dbscan, radius, sor, ....
/// Built once; what the config loader, StreamFilter and kfd-icp-slam's modes use.
const StageRegistry& defaultStageRegistry();

}  // namespace kfd
