#include "kfd/baselines/speckle_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> SpeckleStage::keys() {
    using P = Params;
    return {keys::boolean<P>("speckle_radius", "radius",
                             "speckle stage: radius outlier test instead of the distance test",
                             [](P& p) -> bool& { return p.radius; }),
            keys::real<P>("speckle_max_range", "max_range",
                          "speckle stage: beams farther than this are never removed (m)", 0, 1e6,
                          false, [](P& p) -> double& { return p.max_range; }),
            keys::real<P>("speckle_max_range_difference", "max_range_difference",
                          "speckle stage: largest range difference (distance test) or distance "
                          "(radius test) between beams of a run (m)",
                          0, 1e6, false, [](P& p) -> double& { return p.max_range_difference; }),
            keys::count<P>("speckle_window", "window",
                           "speckle stage: beams per run (distance) or neighbours needed (radius)",
                           1, 100, [](P& p) -> std::size_t& { return p.window; })};
}

}  // namespace kfd
