#include "kfd/baselines/radius_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> RadiusStage::keys() {
    using P = Params;
    return {keys::real<P>("radius_m", "radius_m", "radius stage: neighbourhood radius (m)", 0, 100,
                          true, [](P& p) -> double& { return p.radius_m; }),
            keys::count<P>("radius_min_neighbors", "min_neighbors",
                           "radius stage: other points needed within radius_m (points)", 1, 1e6,
                           [](P& p) -> std::size_t& { return p.min_neighbors; })};
}

}  // namespace kfd
