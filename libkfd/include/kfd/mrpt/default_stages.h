// The stage registry the tools use: the paper's stages, then the baselines.
#pragma once

#include "kfd/baselines/stages.h"
#include "kfd/pipeline/stage_registry.h"

namespace kfd {

/// registerCoreStages() then registerBaselineStages(): distance, keyframe, denoise, motion,
/// dbscan, radius, sor. Built once; what the config loader, StreamFilter and kfd-icp-slam's
/// modes use.
const StageRegistry& defaultStageRegistry();

}  // namespace kfd
