// Keyframe extraction (Sec. 3.1) as a pipeline stage, named "keyframe".
#pragma once

#include <vector>

#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Drops the scans that are not keyframes; never changes a beam. Diagnostics: KeyframeDecision.
class KeyframeStage : public Stage {
  public:
    static constexpr const char* kName = "keyframe";
    static constexpr const char* kHelp =
        "keyframe extraction: drop scans the last keyframe covers (selector = view, kfd's "
        "default) or similar to the window (selector = paper: Sec. 3.1, Formula 3)";
    using Params = KeyframeSelector::Params;
    /// Keys: selector, bins, window, p_pair, max_consecutive_drops, max_interval_s,
    /// max_translation_m, max_rotation_deg, and the view selector's (view_samples,
    /// view_tolerance_m, view_tolerance_deg, max_view_change, change_tolerance_m,
    /// change_tolerance_ratio, max_changed_fraction, degeneracy_ratio, corridor_translation_m,
    /// corridor_rotation_deg, corridor_interval_s).
    static std::vector<StageKey> keys();

    explicit KeyframeStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    void reset() override { algo_.reset(); }
    const KeyframeSelector& algorithm() const { return algo_; }

  private:
    KeyframeSelector algo_;
};

}  // namespace kfd
