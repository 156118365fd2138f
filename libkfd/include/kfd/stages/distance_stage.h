// Algorithm 1 (the distance filter) as a pipeline stage, named "distance".
#pragma once

#include <vector>

#include "kfd/paper/distance_filter.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Never drops a scan; invalidates out-of-range and non-finite beams. Diagnostics:
/// DistanceFilter::Result.
class DistanceStage : public Stage {
  public:
    static constexpr const char* kName = "distance";
    static constexpr const char* kHelp = "Algorithm 1: drop beams outside [min_range, max_range]";
    using Params = DistanceFilter::Params;
    /// Keys: min_range, max_range.
    static std::vector<StageKey> keys();
    /// Its per-scan CSV columns (kfd/pipeline/stage_outputs.h).
    static std::vector<StageColumn> columns();
    /// Its counters of a run (summaries, summary.json).
    static std::vector<StageCounter> counters();

    explicit DistanceStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    const DistanceFilter& algorithm() const { return algo_; }

  private:
    DistanceFilter algo_;
};

}  // namespace kfd
