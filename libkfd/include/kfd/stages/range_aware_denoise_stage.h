// kfd's first denoiser (beyond the paper) as a pipeline stage, named "range_aware_denoise":
// range-aware clustering and a cluster-size bar that follows range.
#pragma once

#include <vector>

#include "kfd/algorithms/range_aware_clustering.h"
#include "kfd/paper/clusters.h"
#include "kfd/pipeline/stage.h"
#include "kfd/pipeline/stage_outputs.h"
#include "kfd/stages/denoise_result.h"

namespace kfd {

/// Never drops a scan; invalidates the points of clusters below the range-adaptive bar
/// (kfd/paper/clusters.h, ClusterFilterParams). Diagnostics: DenoiseResult (RangeAware).
class RangeAwareDenoiseStage : public Stage {
  public:
    static constexpr const char* kName = "range_aware_denoise";
    static constexpr const char* kHelp =
        "kfd's range-aware clustering denoise: breakpoints from incidence and range noise, "
        "clusters smaller than an object of min_object_size_m removed";
    struct Params {
        RangeAwareClustering::Params clustering;  // theta_threshold factor, lambda, sigma
        ClusterFilterParams filter{10, 0.10, 3};  // m_threshold, min_object_size_m, floor
    };
    /// Keys: angle_gap_factor, jump_lambda_deg, jump_sigma_m, m_threshold, min_object_size_m,
    /// min_points_floor.
    static std::vector<StageKey> keys();
    /// Its per-scan CSV columns (kfd/pipeline/stage_outputs.h).
    static std::vector<StageColumn> columns();

    RangeAwareDenoiseStage();  // Params{}
    explicit RangeAwareDenoiseStage(const Params& p);
    const char* name() const override { return kName; }
    bool process(Scan& scan, StageReport& report, const ScanReport& chain) override;
    const Clusters* clusters() const override { return &clusters_; }
    const Params& params() const { return params_; }

  private:
    Params params_;
    RangeAwareClustering clustering_;
    Clusters clusters_;
};

}  // namespace kfd
