#include "kfd/stages/range_aware_denoise_stage.h"

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> RangeAwareDenoiseStage::keys() {
    using P = Params;
    return {
        keys::real<P>("angle_gap_factor", "angle_gap_factor",
                      "theta_threshold in multiples of the angular resolution (as Sec. 3.2.2)", 0,
                      1e4, true, [](P& p) -> double& { return p.clustering.angle_gap_factor; }),
        keys::count<P>("m_threshold", "m_threshold",
                       "clusters with fewer points are noise (the bar's upper clamp)", 1, 1e6,
                       [](P& p) -> std::size_t& { return p.filter.m_threshold; }),
        keys::real<P>("jump_lambda_deg", "jump_lambda_deg",
                      "breakpoint incidence limit lambda (deg)", 0, 89.9, true,
                      [](P& p) -> double& { return p.clustering.jump_lambda_deg; }),
        keys::real<P>("jump_sigma_m", "jump_sigma_m", "sensor range noise sigma (m)", 0, 10, false,
                      [](P& p) -> double& { return p.clustering.jump_sigma_m; }),
        keys::real<P>("min_object_size_m", "min_object_size_m",
                      "width of the smallest object kept (m)", 0, 100, false,
                      [](P& p) -> double& { return p.filter.min_object_size_m; }),
        keys::count<P>("min_points_floor", "min_points_floor",
                       "fewest points a kept cluster may have", 1, 1e6,
                       [](P& p) -> std::size_t& { return p.filter.min_points_floor; })};
}

RangeAwareDenoiseStage::RangeAwareDenoiseStage() : RangeAwareDenoiseStage(Params{}) {}

RangeAwareDenoiseStage::RangeAwareDenoiseStage(const Params& p) : params_(p) {
    if (p.filter.m_threshold < 1) throw ParameterError("m_threshold", "m_threshold must be >= 1");
    if (!(p.filter.min_object_size_m >= 0.0))
        throw ParameterError("min_object_size_m", "min_object_size_m must be >= 0");
    if (p.filter.min_points_floor < 1)
        throw ParameterError("min_points_floor", "min_points_floor must be >= 1");
    clustering_.initialize(p.clustering);
}

bool RangeAwareDenoiseStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    DenoiseResult res = startDenoising(scan, DenoiseVariant::RangeAware);
    const auto r = clustering_.cluster(scan, clusters_);
    res.merges = r.merges;
    res.theta_threshold = r.theta_threshold;
    res.points_removed += filterClusters(params_.filter, scan, clusters_);
    return endDenoising(clusters_, res, report);
}

std::vector<StageColumn> RangeAwareDenoiseStage::columns() { return denoiseColumns(); }

}  // namespace kfd
