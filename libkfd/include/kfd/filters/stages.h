// laser_filters-style stages (beam_count, angle_bounds, footprint, intensity) and their
// registration.
#pragma once

#include "kfd/filters/angle_bounds.h"
#include "kfd/filters/beam_count.h"
#include "kfd/filters/footprint.h"
#include "kfd/filters/intensity_filter.h"
#include "kfd/pipeline/stage_registry.h"

namespace kfd {

/// Registers the filters a laser_filters chain usually holds before SLAM: beam_count,
/// angle_bounds, footprint, intensity.
void registerFilterStages(StageRegistry& registry);

}  // namespace kfd
