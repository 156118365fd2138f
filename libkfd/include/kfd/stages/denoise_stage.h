// Clustering denoise (Sec. 3.2) as a pipeline stage, named "denoise".
#pragma once

#include <vector>

#include "kfd/algorithms/denoiser.h"
#include "kfd/pipeline/stage.h"

namespace kfd {

/// Never drops a scan; invalidates the points of noise clusters. Diagnostics: Denoiser::Result.
class DenoiseStage : public DenoisingStage<Denoiser> {
  public:
    static constexpr const char* kName = "denoise";
    static constexpr const char* kHelp =
        "clustering denoise (Sec. 3.2, Algorithm 2): drop points of small clusters";
    /// Keys: variant, rings, ring_r_max, angle_gap_factor, merge_distance_m, m_threshold,
    /// jump_lambda_deg, jump_sigma_m, min_object_size_m, min_points_floor, and the evidence
    /// variant's incidence_deg, sigma_m, max_gap_beams, max_small_points, temporal,
    /// pose_trans_error_m, pose_rot_error_deg, motion_error_fraction, max_removed_fraction,
    /// temporal_scans, next_scan.
    static std::vector<StageKey> keys();

    explicit DenoiseStage(const Params& p = {}) : DenoisingStage(p) {}
    const char* name() const override { return kName; }
    void reset() override { mutableAlgorithm().reset(); }
    /// The evidence variant's temporal evidence from the scans the keyframe stage drops.
    void observeDropped(const Scan& scan) override { mutableAlgorithm().observe(scan); }
    /// next_scan (evidence variant, temporal on): a keyframe waits for the next scan.
    bool defers() const override { return algorithm().wantsNextScan(); }
    bool finish(Scan& scan, StageReport& report, const ScanReport&, const Scan* next) override {
        const auto r = mutableAlgorithm().filter(scan, next);
        report.noise = true;
        report.points_removed = r.points_removed;
        report.setDiagnostics(r);
        return true;
    }
};

}  // namespace kfd
