// The keyframe guards' keys, declared once for both keyframe stages (keyframe, view_keyframe),
// whose Params derive from KeyframeGuards::Params.
#pragma once

#include <vector>

#include "kfd/algorithms/keyframe_guards.h"
#include "kfd/pipeline/stage_keys.h"

namespace kfd {

template <class P>
std::vector<StageKey> guardKeys() {
    return {keys::count<P>("max_consecutive_drops", "max_consecutive_drops",
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

}  // namespace kfd
