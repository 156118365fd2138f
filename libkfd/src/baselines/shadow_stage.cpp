#include "kfd/baselines/shadow_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> ShadowStage::keys() {
    using P = Params;
    return {
        keys::real<P>("shadow_min_angle_deg", "min_angle_deg",
                      "shadow stage: smallest allowed angle to the ray (deg)", 0, 180, false,
                      [](P& p) -> double& { return p.min_angle_deg; }),
        keys::real<P>("shadow_max_angle_deg", "max_angle_deg",
                      "shadow stage: largest allowed angle to the ray (deg)", 0, 180, false,
                      [](P& p) -> double& { return p.max_angle_deg; }),
        keys::count<P>("shadow_window", "window", "shadow stage: beams each side tested (beams)", 1,
                       64, [](P& p) -> std::size_t& { return p.window; }),
        keys::count<P>("shadow_neighbors", "neighbors",
                       "shadow stage: beams each side removed when farther (beams)", 0, 1000,
                       [](P& p) -> std::size_t& { return p.neighbors; }),
        keys::boolean<P>("shadow_remove_start", "remove_start",
                         "shadow stage: also remove the beam whose angle test failed",
                         [](P& p) -> bool& { return p.remove_start; })};
}

}  // namespace kfd
