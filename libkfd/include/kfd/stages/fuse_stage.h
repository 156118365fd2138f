// Fused keyframes (issue 25) as a pipeline stage, named "fuse": after `keyframe`, it keeps the
// scans the keyframe stage dropped and fuses them into the next keyframe
// (kfd/algorithms/scan_fusion.h).
#pragma once

#include <vector>

#include "kfd/algorithms/scan_fusion.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Never drops a scan and never removes a point: replaces a keyframe's valid ranges by a robust
/// estimate over the dropped scans (Stage::observeDropped) since the previous keyframe.
/// Diagnostics: ScanFusion::Result. Laser only (no odometry): nothing is fused.
class FuseStage : public Stage {
  public:
    static constexpr const char* kName = "fuse";
    static constexpr const char* kHelp =
        "fused keyframes: each keyframe range becomes the median of the returns of the scans "
        "dropped since the previous keyframe that agree with it (put after keyframe; needs "
        "odometry)";
    using Params = ScanFusion::Params;
    /// Keys: fuse_max_scans, fuse_min_agreeing, fuse_gate_sigmas, fuse_max_bias_sigmas,
    /// fuse_estimator, fuse_min_sigma_m, fuse_max_step_m, fuse_max_step_deg,
    /// fuse_max_span_beams, fuse_refine_iterations, fuse_refine_samples, fuse_refine_gate_m.
    static std::vector<StageKey> keys();

    explicit FuseStage(const Params& p = {}) : algo_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    void observeDropped(const Scan& scan, const ScanReport&) override { algo_.observe(scan); }
    void reset() override { algo_.reset(); }
    const ScanFusion& algorithm() const { return algo_; }

  private:
    ScanFusion algo_;
};

}  // namespace kfd
