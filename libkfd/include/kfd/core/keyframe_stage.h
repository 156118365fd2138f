// Keyframe extraction (Sec. 3.1) as a pipeline stage, named "keyframe".
#pragma once

#include <vector>

#include "kfd/core/keyframe_selector.h"
#include "kfd/core/stage.h"

namespace kfd {

/// Drops the scans that are not keyframes; never changes a beam. Diagnostics: KeyframeDecision.
class KeyframeStage : public Stage {
  public:
    static constexpr const char* kName = "keyframe";
    static constexpr const char* kHelp =
        "keyframe extraction (Sec. 3.1, Formula 3): drop scans similar to the window";
    using Params = KeyframeSelector::Params;
    /// Keys: bins, window, p_pair, max_consecutive_drops, max_interval_s, max_translation_m,
    /// max_rotation_deg.
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
