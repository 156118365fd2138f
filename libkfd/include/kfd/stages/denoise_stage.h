// The paper's clustering denoise (Sec. 3.2, Algorithm 2) as a pipeline stage, named "denoise":
// runs the paper's code only (kfd/paper/ring_clustering.h, kfd/paper/clusters.h).
#pragma once

#include <cstddef>
#include <vector>

#include "kfd/paper/clusters.h"
#include "kfd/paper/ring_clustering.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"
#include "kfd/stages/denoise_result.h"

namespace kfd {

/// Never drops a scan; invalidates the points of clusters smaller than m_threshold.
/// Diagnostics: DenoiseResult (variant Reference).
class DenoiseStage : public Stage {
  public:
    static constexpr const char* kName = "denoise";
    static constexpr const char* kHelp =
        "the paper's clustering denoise (Sec. 3.2, Algorithm 2): equal-area rings, angle-gap "
        "blocks merged across rings, clusters below m_threshold removed";
    struct Params {
        /// t, r_max (Formulas 6-8), theta_threshold factor (Sec. 3.2.2), d_threshold (Formula 10)
        RingClustering::Params clustering;
        std::size_t m_threshold = 10;  // points; Sec. 3.2.4: smaller clusters are noise
    };
    /// Keys: rings, ring_r_max, angle_gap_factor, merge_distance_m, m_threshold.
    static std::vector<StageKey> keys();
    /// Its per-scan CSV columns (kfd/pipeline/stage_outputs.h).
    static std::vector<StageColumn> columns();

    DenoiseStage();  // Params{}
    explicit DenoiseStage(const Params& p);
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    const Clusters* clusters() const override { return &clusters_; }
    const Params& params() const { return params_; }

  private:
    Params params_;
    RingClustering clustering_;
    Clusters clusters_;
};

}  // namespace kfd
