// kfd's evidence denoiser (beyond the paper; kfd's default) as a pipeline stage, named
// "evidence_denoise": spatial and temporal evidence, thresholds from the scans.
#pragma once

#include <vector>

#include "kfd/algorithms/evidence_filter.h"
#include "kfd/paper/clusters.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"
#include "kfd/stages/denoise_result.h"

namespace kfd {

/// Never drops a scan; invalidates the returns the evidence says are noise
/// (kfd/algorithms/evidence_filter.h). Learns from the scans an earlier stage drops
/// (observeDropped); with next_scan (and temporal) a keyframe waits for the sensor's next scan.
/// Diagnostics: DenoiseResult (variant Evidence).
class EvidenceDenoiseStage : public Stage {
  public:
    static constexpr const char* kName = "evidence_denoise";
    static constexpr const char* kHelp =
        "kfd's evidence denoise: segments by adaptive breakpoints, temporal evidence from the "
        "last keyframes and raw scans, at most max_removed_fraction of a scan removed";
    using Params = EvidenceFilter::Params;
    /// Keys: min_object_size_m, incidence_deg, sigma_m, max_gap_beams, max_small_points,
    /// temporal, pose_trans_error_m, pose_rot_error_deg, motion_error_fraction,
    /// max_removed_fraction, max_confirmed_fraction, confirm_support, temporal_scans, next_scan.
    static std::vector<StageKey> keys();
    /// Its per-scan CSV columns (kfd/pipeline/stage_outputs.h).
    static std::vector<StageColumn> columns();
    /// Its counters of a run (summaries, summary.json).
    static std::vector<StageCounter> counters();

    explicit EvidenceDenoiseStage(const Params& p = {}) : filter_(p) {}
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override {
        return finish(scan, report, chain, nullptr);
    }
    /// The evidence's temporal part from the scans the keyframe stage drops.
    void observeDropped(const Scan& scan, const ScanReport& chain) override;
    void reset() override { filter_.reset(); }
    /// next_scan (with temporal): a keyframe waits for the next scan.
    bool defers() const override { return filter_.params().next_scan && filter_.params().temporal; }
    bool finish(Scan& scan, StageReport& report, const ScanReport& chain,
                const Scan* next) override;
    const Clusters* clusters() const override { return &clusters_; }
    const EvidenceFilter& algorithm() const { return filter_; }

  private:
    EvidenceFilter filter_;
    Clusters clusters_;
};

}  // namespace kfd
