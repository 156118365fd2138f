// Statistical outlier removal as a pipeline stage, named "sor" (baseline, beyond the paper).
#pragma once

#include <vector>

#include "kfd/baselines/statistical_outlier.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Never drops a scan; invalidates noise points. Diagnostics: StatisticalOutlierFilter::Result.
class SorStage : public DenoisingStage<StatisticalOutlierFilter> {
  public:
    static constexpr const char* kName = "sor";
    static constexpr const char* kHelp =
        "baseline: statistical outlier removal (PCL's StatisticalOutlierRemoval)";
    /// Keys: sor_k, sor_std_mul.
    static std::vector<StageKey> keys();

    explicit SorStage(const Params& p = {}) : DenoisingStage(p) {}
    const char* name() const override { return kName; }
};

}  // namespace kfd
