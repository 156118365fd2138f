// Radius outlier removal as a pipeline stage, named "radius" (baseline, beyond the paper).
#pragma once

#include <vector>

#include "kfd/baselines/radius_outlier.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Never drops a scan; invalidates noise points. Diagnostics: RadiusOutlierFilter::Result.
class RadiusStage : public DenoisingStage<RadiusOutlierFilter> {
  public:
    static constexpr const char* kName = "radius";
    static constexpr const char* kHelp =
        "baseline: radius outlier removal (PCL's RadiusOutlierRemoval)";
    /// Keys: radius_m, radius_min_neighbors.
    static std::vector<StageKey> keys();

    explicit RadiusStage(const Params& p = {}) : DenoisingStage(p) {}
    const char* name() const override { return kName; }
};

}  // namespace kfd
