// Statistical outlier removal as a pipeline stage, named "sor" (baseline, beyond the paper).
#pragma once

#include <vector>

#include "kfd/baselines/statistical_outlier.h"
#include "kfd/core/stage.h"

namespace kfd {

/// Never drops a scan; invalidates noise points. Diagnostics: StatisticalOutlierFilter::Result.
class SorStage : public Stage {
  public:
    static constexpr const char* kName = "sor";
    static constexpr const char* kHelp =
        "baseline: statistical outlier removal (PCL's StatisticalOutlierRemoval)";
    using Params = StatisticalOutlierFilter::Params;
    /// Keys: sor_k, sor_std_mul.
    static std::vector<StageKey> keys();

    explicit SorStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    const StatisticalOutlierFilter& filter() const { return algo_; }

  private:
    StatisticalOutlierFilter algo_;
};

}  // namespace kfd
