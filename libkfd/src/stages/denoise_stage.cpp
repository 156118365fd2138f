#include "kfd/stages/denoise_stage.h"

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> DenoiseStage::keys() {
    using P = Params;
    return {keys::count<P>("rings", "rings", "Sec. 3.2.1: equal-area rings t", 1, 254,
                           [](P& p) -> std::size_t& { return p.clustering.rings.rings; }),
            keys::real<P>("ring_r_max", "r_max",
                          "Formulas 6-8: outer ring radius (m, 0 = farthest point)", 0, 1000, false,
                          [](P& p) -> double& { return p.clustering.rings.r_max; }),
            keys::real<P>("angle_gap_factor", "angle_gap_factor",
                          "Sec. 3.2.2: theta_threshold in multiples of the angular resolution", 0,
                          1e4, true, [](P& p) -> double& { return p.clustering.angle_gap_factor; }),
            keys::real<P>(
                "merge_distance_m", "merge_distance_m",
                "Formula 10: d_threshold (m, 0 = chord of theta_threshold at the boundary)", 0,
                1000, false, [](P& p) -> double& { return p.clustering.merge_distance_m; }),
            keys::count<P>("m_threshold", "m_threshold",
                           "Sec. 3.2.4: clusters with fewer points are noise", 1, 1e6,
                           [](P& p) -> std::size_t& { return p.m_threshold; })};
}

DenoiseStage::DenoiseStage() : DenoiseStage(Params{}) {}

DenoiseStage::DenoiseStage(const Params& p) : params_(p) {
    if (p.m_threshold < 1) throw ParameterError("m_threshold", "m_threshold must be >= 1");
    clustering_.initialize(p.clustering);
}

bool DenoiseStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    DenoiseResult res = startDenoising(scan, DenoiseVariant::Reference);
    const auto r = clustering_.cluster(scan, clusters_);  // Algorithm 2
    res.blocks = r.blocks;
    res.merges = r.merges;
    res.r_max = r.r_max;
    res.theta_threshold = r.theta_threshold;
    // Sec. 3.2.4: the fixed bar (min_object_size_m = 0).
    const ClusterFilterParams bar{params_.m_threshold, 0.0, 3};
    res.points_removed += filterClusters(bar, scan, clusters_);
    return endDenoising(clusters_, res, report);
}

std::vector<StageColumn> DenoiseStage::columns() { return denoiseColumns(); }

}  // namespace kfd
