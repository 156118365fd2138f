#include "kfd/baselines/dbscan_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> DbscanStage::keys() {
    using P = Params;
    return {keys::real<P>("dbscan_eps_m", "eps_m", "dbscan stage: neighbourhood radius Eps (m)", 0,
                          100, true, [](P& p) -> double& { return p.eps_m; }),
            keys::count<P>("dbscan_min_pts", "min_pts",
                           "dbscan stage: minPts (the point itself included)", 1, 1e6,
                           [](P& p) -> std::size_t& { return p.min_pts; })};
}

}  // namespace kfd
