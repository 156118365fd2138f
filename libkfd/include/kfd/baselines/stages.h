// The baseline stages (motion, dbscan, radius, sor, shadow, speckle, decimate) and their
// registration.
#pragma once

#include "kfd/baselines/dbscan_stage.h"
#include "kfd/baselines/decimate_stage.h"
#include "kfd/baselines/motion_stage.h"
#include "kfd/baselines/radius_stage.h"
#include "kfd/baselines/shadow_stage.h"
#include "kfd/baselines/sor_stage.h"
#include "kfd/baselines/speckle_stage.h"
#include "kfd/pipeline/stage_registry.h"

namespace kfd {

/// Registers the baselines after the core stages: motion (odometry motion filter), dbscan
/// (DBSCAN denoise), radius (radius outlier removal), sor (statistical outlier removal),
/// shadow and speckle (ROS laser_filters' two filters), decimate (uniform decimation).
void registerBaselineStages(StageRegistry& registry);

}  // namespace kfd
