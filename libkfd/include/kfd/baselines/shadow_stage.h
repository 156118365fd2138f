// The shadow filter as a pipeline stage, named "shadow" (baseline, beyond the paper).
#pragma once

#include <vector>

#include "kfd/baselines/shadow_filter.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Never drops a scan; invalidates veiling points. Diagnostics: ShadowFilter::Result.
class ShadowStage : public DenoisingStage<ShadowFilter> {
  public:
    static constexpr const char* kName = "shadow";
    static constexpr const char* kHelp =
        "baseline: shadow / veiling point filter (ROS laser_filters' ScanShadowsFilter)";
    /// Keys: shadow_min_angle_deg, shadow_max_angle_deg, shadow_window, shadow_neighbors,
    /// shadow_remove_start.
    static std::vector<StageKey> keys();

    explicit ShadowStage(const Params& p = {}) : DenoisingStage(p) {}
    const char* name() const override { return kName; }
};

}  // namespace kfd
