// The odometry motion filter as a pipeline stage, named "motion" (baseline, beyond the paper).
#pragma once

#include <vector>

#include "kfd/baselines/motion_filter.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Drops the scans taken before enough motion; never changes a beam. No diagnostics.
class MotionStage : public Stage {
  public:
    static constexpr const char* kName = "motion";
    static constexpr const char* kHelp =
        "baseline: keep a scan only after enough odometry motion (Cartographer's motion filter)";
    using Params = MotionFilter::Params;
    /// Keys: motion_distance_m, motion_angle_deg, motion_interval_s.
    static std::vector<StageKey> keys();

    explicit MotionStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    void reset() override { algo_.reset(); }
    const MotionFilter& algorithm() const { return algo_; }

  private:
    MotionFilter algo_;
};

}  // namespace kfd
