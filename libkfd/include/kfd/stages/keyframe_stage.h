// The paper's keyframe extraction (Sec. 3.1, Formula 3) as a pipeline stage, named "keyframe".
#pragma once

#include <vector>

#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Drops the scans whose histogram is similar to the window's (Formula 3); never changes a
/// beam. kfd's guards (0 = off; off in the paper presets) force a keyframe.
/// Diagnostics: KeyframeDecision.
class KeyframeStage : public Stage {
  public:
    static constexpr const char* kName = "keyframe";
    static constexpr const char* kHelp =
        "the paper's keyframe extraction (Sec. 3.1, Formula 3): drop scans whose range "
        "histogram correlates with the last m keyframes'";
    using Params = KeyframeSelector::Params;
    /// Keys: bins, window, p_pair, and the guards max_consecutive_drops, max_interval_s,
    /// max_translation_m, max_rotation_deg.
    static std::vector<StageKey> keys();
    /// Its per-scan CSV columns (kfd/pipeline/stage_outputs.h).
    static std::vector<StageColumn> columns();

    explicit KeyframeStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    void reset() override { algo_.reset(); }
    const KeyframeSelector& algorithm() const { return algo_; }

  private:
    KeyframeSelector algo_;
};

}  // namespace kfd
