// The odometry check (issue 22) as a pipeline stage, named "odometry_check": put first, so that
// every later stage sees only the odometry the scans do not contradict.
#pragma once

#include <vector>

#include "kfd/algorithms/odometry_check.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Never drops a scan and never removes a point; withholds or rebases the scan's odometry.
/// Diagnostics: OdometryCheck::Result.
class OdometryCheckStage : public Stage {
  public:
    static constexpr const char* kName = "odometry_check";
    static constexpr const char* kHelp =
        "withhold odometry the scans contradict (frozen while they change, jumps they do not "
        "show): later stages decide laser only there";
    using Params = OdometryCheck::Params;
    /// Keys: frozen_changed_fraction, jump_margin.
    static std::vector<StageKey> keys();
    /// Its per-scan CSV columns (kfd/pipeline/stage_outputs.h).
    static std::vector<StageColumn> columns();
    /// Its counters of a run (summaries, summary.json).
    static std::vector<StageCounter> counters();

    explicit OdometryCheckStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    void reset() override { algo_.reset(); }
    const OdometryCheck& algorithm() const { return algo_; }

  private:
    OdometryCheck algo_;
};

}  // namespace kfd
