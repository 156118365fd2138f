#include "kfd/core/denoise_stage.h"

#include "kfd/core/stage_keys.h"

namespace kfd {
namespace {

using P = DenoiseStage::Params;

// One key for both variants' theta_threshold factor (printed from the reference variant's).
StageKey angleGapKey() {
    StageKey k =
        keys::real<P>("angle_gap_factor", "angle_gap_factor",
                      "Sec. 3.2.2: theta_threshold in multiples of the angular resolution", 0, 1e4,
                      true, [](P& p) -> double& { return p.reference.angle_gap_factor; });
    k.set = [set = k.set](void* params, const std::string& text) {
        set(params, text);
        auto& p = *static_cast<P*>(params);
        p.range_aware.angle_gap_factor = p.reference.angle_gap_factor;
    };
    return k;
}

}  // namespace

std::vector<StageKey> DenoiseStage::keys() {
    return {
        keys::custom<P>(
            "variant", "variant", "denoiser: reference (the paper) or range_aware (kfd's)",
            "reference, range_aware",
            [](P& p, const std::string& text) { p.variant = parseDenoiseVariant(text); },
            [](const P& p) { return std::string(toString(p.variant)); }),
        keys::count<P>("rings", "rings", "Sec. 3.2.1: equal-area rings t", 1, 254,
                       [](P& p) -> std::size_t& { return p.reference.rings.rings; }),
        keys::real<P>("ring_r_max", "r_max",
                      "Formulas 6-8: outer ring radius (m, 0 = farthest point)", 0, 1000, false,
                      [](P& p) -> double& { return p.reference.rings.r_max; }),
        angleGapKey(),
        keys::real<P>("merge_distance_m", "merge_distance_m",
                      "Formula 10: d_threshold (m, 0 = chord of theta_threshold at the boundary)",
                      0, 1000, false, [](P& p) -> double& { return p.reference.merge_distance_m; }),
        keys::count<P>("m_threshold", "m_threshold",
                       "Sec. 3.2.4: clusters with fewer points are noise", 1, 1e6,
                       [](P& p) -> std::size_t& { return p.filter.m_threshold; }),
        keys::real<P>("jump_lambda_deg", "jump_lambda_deg",
                      "range_aware: breakpoint incidence limit lambda (deg)", 0, 89.9, true,
                      [](P& p) -> double& { return p.range_aware.jump_lambda_deg; }),
        keys::real<P>("jump_sigma_m", "jump_sigma_m", "range_aware: sensor range noise sigma (m)",
                      0, 10, false, [](P& p) -> double& { return p.range_aware.jump_sigma_m; }),
        keys::real<P>("min_object_size_m", "min_object_size_m",
                      "range_aware: object width that needs m_threshold points (m)", 0, 100, false,
                      [](P& p) -> double& { return p.filter.min_object_size_m; }),
        keys::count<P>("min_points_floor", "min_points_floor",
                       "range_aware: fewest points a kept cluster may have", 1, 1e6,
                       [](P& p) -> std::size_t& { return p.filter.min_points_floor; })};
}

}  // namespace kfd
