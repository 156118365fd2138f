// kfd's keyframe rule (issue 12) as a pipeline stage, named "view_keyframe" (kfd's default).
#pragma once

#include <vector>

#include "kfd/algorithms/view_keyframe_selector.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Drops the scans the last keyframe's view covers; never changes a beam. The guards force a
/// keyframe. Diagnostics: KeyframeDecision.
class ViewKeyframeStage : public Stage {
  public:
    static constexpr const char* kName = "view_keyframe";
    static constexpr const char* kHelp =
        "kfd's keyframe extraction: drop scans whose view the last keyframe covers (point "
        "displacement from odometry, or the share of changed returns without it)";
    using Params = ViewKeyframeSelector::Params;
    /// Keys: view_samples, view_tolerance_m, view_tolerance_deg, max_view_change,
    /// change_tolerance_m, change_tolerance_ratio, max_changed_fraction, degeneracy_ratio,
    /// corridor_translation_m, corridor_rotation_deg, corridor_interval_s, and the guards.
    static std::vector<StageKey> keys();
    /// Its per-scan CSV columns (kfd/pipeline/stage_outputs.h).
    static std::vector<StageColumn> columns();
    /// Its counters of a run (summaries, summary.json).
    static std::vector<StageCounter> counters();

    explicit ViewKeyframeStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    void reset() override { algo_.reset(); }
    const ViewKeyframeSelector& algorithm() const { return algo_; }

  private:
    ViewKeyframeSelector algo_;
};

}  // namespace kfd
