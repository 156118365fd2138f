#include "kfd/core/keyframe_stage.h"

#include "kfd/core/stage_keys.h"

namespace kfd {

std::vector<StageKey> KeyframeStage::keys() {
    using P = Params;
    return {keys::count<P>("bins", "bins", "Sec. 3.1.2: histogram columns n", 2, 4096,
                           [](P& p) -> std::size_t& { return p.bins; }),
            keys::count<P>("window", "window", "Sec. 3.1.4: sliding window m (keyframes compared)",
                           1, 1024, [](P& p) -> std::size_t& { return p.window; }),
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
                          "guard: force a keyframe after D metres of odometry (0 = off)", 0, 1e6,
                          false, [](P& p) -> double& { return p.max_translation_m; }),
            keys::real<P>("max_rotation_deg", "max_rotation_deg",
                          "guard: force a keyframe after A degrees of odometry turn (0 = off)", 0,
                          360, false, [](P& p) -> double& { return p.max_rotation_deg; })};
}

bool KeyframeStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    const KeyframeDecision d = algo_.filter(scan);
    report.setDiagnostics(d);
    return d.keyframe;
}

}  // namespace kfd
