#include "kfd/stages/denoise_stage.h"

#include "kfd/pipeline/stage_keys.h"

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
            "variant", "variant",
            "denoiser: reference (the paper), range_aware or evidence (kfd's default)",
            "reference, range_aware, evidence",
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
                      "range_aware, evidence: width of the smallest object kept (m)", 0, 100, false,
                      [](P& p) -> double& { return p.filter.min_object_size_m; }),
        keys::count<P>("min_points_floor", "min_points_floor",
                       "range_aware: fewest points a kept cluster may have", 1, 1e6,
                       [](P& p) -> std::size_t& { return p.filter.min_points_floor; }),
        keys::real<P>("incidence_deg", "incidence_deg",
                      "evidence: breakpoint incidence limit lambda (deg)", 0, 89.9, true,
                      [](P& p) -> double& { return p.evidence.incidence_deg; }),
        keys::real<P>("sigma_m", "sigma_m",
                      "evidence: sensor range noise (m), 0 = estimated from the scans", 0, 10,
                      false, [](P& p) -> double& { return p.evidence.sigma_m; }),
        keys::count<P>("max_gap_beams", "max_gap_beams",
                       "evidence: missing beams a surface may span", 0, 16,
                       [](P& p) -> std::size_t& { return p.evidence.max_gap_beams; }),
        keys::count<P>("max_small_points", "max_small_points",
                       "evidence: segments of at most this many points may be small", 0, 1000,
                       [](P& p) -> std::size_t& { return p.evidence.max_small_points; }),
        keys::boolean<P>("temporal", "temporal",
                         "evidence: compare with the previous keyframe (needs odometry)",
                         [](P& p) -> bool& { return p.evidence.temporal; }),
        keys::real<P>("pose_trans_error_m", "pose_trans_error_m",
                      "evidence: odometry translation error of one keyframe step (m)", 0, 10, false,
                      [](P& p) -> double& { return p.evidence.pose_trans_error_m; }),
        keys::real<P>("pose_rot_error_deg", "pose_rot_error_deg",
                      "evidence: odometry rotation error of one keyframe step (deg)", 0, 90, false,
                      [](P& p) -> double& { return p.evidence.pose_rot_error_deg; }),
        keys::real<P>("motion_error_fraction", "motion_error_fraction",
                      "evidence: odometry error per metre and per radian of the step", 0, 10, false,
                      [](P& p) -> double& { return p.evidence.motion_error_fraction; }),
        keys::real<P>("max_removed_fraction", "max_removed_fraction",
                      "evidence: largest share of a scan's valid returns removed (step 5)", 0, 1,
                      true, [](P& p) -> double& { return p.evidence.max_removed_fraction; }),
        keys::real<P>("max_confirmed_fraction", "max_confirmed_fraction",
                      "evidence: removal beyond the bound kept up to this share when the raw "
                      "scan just before confirms it (step 5; 0 = off)",
                      0, 1, false,
                      [](P& p) -> double& { return p.evidence.max_confirmed_fraction; }),
        keys::real<P>("confirm_support", "confirm_support",
                      "evidence: ... when it supports this share of the other returns it judged", 0,
                      1, true, [](P& p) -> double& { return p.evidence.confirm_support; }),
        keys::count<P>("temporal_scans", "temporal_scans",
                       "evidence: raw scans kept before a keyframe (the dropped ones) as "
                       "temporal evidence with margins from their alignment; 0 = keyframes only",
                       0, 16, [](P& p) -> std::size_t& { return p.evidence.temporal_scans; }),
        keys::boolean<P>("next_scan", "next_scan",
                         "evidence: also confirm a keyframe against the scan just after it (one "
                         "scan of latency: the keyframe is output when the next scan arrives)",
                         [](P& p) -> bool& { return p.evidence.next_scan; })};
}

}  // namespace kfd
