#include "kfd/stages/keyframe_stage.h"

#include "kfd/pipeline/stage_keys.h"

#include <string>

namespace kfd {

std::vector<StageKey> KeyframeStage::keys() {
    using P = Params;
    auto viewReal = [](const char* name, const char* help, double lo, double hi, bool lo_open,
                       double ViewSelector::Params::*member) {
        std::string field = name;  // the Params field: the key without "view_"
        if (field.rfind("view_", 0) == 0) field = field.substr(5);
        return keys::real<P>(name, field, help, lo, hi, lo_open,
                             [member](P& p) -> double& { return p.view.*member; });
    };
    using V = ViewSelector::Params;
    return {
        keys::custom<P>(
            "selector", "selector",
            "novelty rule: paper (Formula 3, histogram correlation) or view (kfd's default)",
            "paper, view",
            [](P& p, const std::string& text) { p.selector = parseKeyframeRule(text); },
            [](const P& p) { return std::string(toString(p.selector)); }),
        keys::count<P>("bins", "bins", "Sec. 3.1.2: histogram columns n", 2, 4096,
                       [](P& p) -> std::size_t& { return p.bins; }),
        keys::count<P>("window", "window", "Sec. 3.1.4: sliding window m (keyframes compared)", 1,
                       1024, [](P& p) -> std::size_t& { return p.window; }),
        keys::real<P>("p_pair", "p_pair",
                      "Formula 3: pairwise similarity threshold; P_threshold = P_pair^m", 0, 1,
                      true, [](P& p) -> double& { return p.p_pair; }),
        keys::count<P>("max_consecutive_drops", "max_consecutive_drops",
                       "guard: force a keyframe after K drops (0 = off)", 0, 1e9,
                       [](P& p) -> std::size_t& { return p.max_consecutive_drops; }),
        keys::real<P>("max_interval_s", "max_interval_s",
                      "guard: force a keyframe after T seconds (0 = off)", 0, 1e9, false,
                      [](P& p) -> double& { return p.max_interval_s; }),
        keys::real<P>("max_translation_m", "max_translation_m",
                      "guard: force a keyframe after D metres of odometry (0 = off)", 0, 1e6, false,
                      [](P& p) -> double& { return p.max_translation_m; }),
        keys::real<P>("max_rotation_deg", "max_rotation_deg",
                      "guard: force a keyframe after A degrees of odometry turn (0 = off)", 0, 360,
                      false, [](P& p) -> double& { return p.max_rotation_deg; }),
        keys::count<P>("view_samples", "max_samples",
                       "view: beams sampled per scan (every k-th, k = ceil(beams / this))", 2,
                       65536, [](P& p) -> std::size_t& { return p.view.max_samples; }),
        viewReal("view_tolerance_m", "view: displacement unit a of a point at range 0 (m)", 0, 1e3,
                 true, &V::tolerance_m),
        viewReal("view_tolerance_deg", "view: the unit grows by r tan(b) at range r (b, deg)", 0,
                 89.9, false, &V::tolerance_deg),
        viewReal("max_view_change",
                 "view, odometry: keyframe at this RMS point displacement (units a + r tan b)", 0,
                 1e3, true, &V::max_view_change),
        viewReal("change_tolerance_m", "view, laser only: a range changed beyond this (m) ...", 0,
                 1e3, false, &V::change_tolerance_m),
        viewReal("change_tolerance_ratio", "view, laser only: ... plus this share of the range", 0,
                 10, false, &V::change_tolerance_ratio),
        viewReal("max_changed_fraction",
                 "view, laser only: keyframe when this share of the returns changed", 0, 1, true,
                 &V::max_changed_fraction),
        viewReal("degeneracy_ratio",
                 "corridor switch: degenerate below lambda_min/lambda_max of the normals "
                 "(0 = off)",
                 0, 1, false, &V::degeneracy_ratio),
        viewReal("corridor_translation_m",
                 "corridor switch, odometry: keyframe after this travel (m)", 0, 1e6, true,
                 &V::corridor_translation_m),
        viewReal("corridor_rotation_deg",
                 "corridor switch, odometry: keyframe after this turn (deg)", 0, 360, true,
                 &V::corridor_rotation_deg),
        viewReal("corridor_interval_s", "corridor switch, laser only: keyframe after this time (s)",
                 0, 1e6, true, &V::corridor_interval_s)};
}

bool KeyframeStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    const KeyframeDecision d = algo_.filter(scan);
    report.setDiagnostics(d);
    return d.keyframe;
}

}  // namespace kfd
