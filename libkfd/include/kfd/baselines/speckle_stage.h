// The speckle filter as a pipeline stage, named "speckle" (baseline, beyond the paper).
#pragma once

#include <vector>

#include "kfd/baselines/speckle_filter.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Never drops a scan; invalidates speckles. Diagnostics: SpeckleFilter::Result.
class SpeckleStage : public DenoisingStage<SpeckleFilter> {
  public:
    static constexpr const char* kName = "speckle";
    static constexpr const char* kHelp =
        "baseline: speckle filter (ROS laser_filters' LaserScanSpeckleFilter)";
    /// Keys: speckle_radius, speckle_max_range, speckle_max_range_difference, speckle_window.
    static std::vector<StageKey> keys();

    explicit SpeckleStage(const Params& p = {}) : DenoisingStage(p) {}
    const char* name() const override { return kName; }
};

}  // namespace kfd
