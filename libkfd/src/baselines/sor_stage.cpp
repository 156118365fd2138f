#include "kfd/baselines/sor_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> SorStage::keys() {
    using P = Params;
    return {keys::count<P>("sor_k", "k", "sor stage: nearest neighbours per point (points)", 1,
                           kMaxSorNeighbours, [](P& p) -> std::size_t& { return p.k; }),
            keys::real<P>("sor_std_mul", "std_mul",
                          "sor stage: noise above mean + sor_std_mul x stddev of the mean "
                          "neighbour distance (standard deviations)",
                          0, 100, false, [](P& p) -> double& { return p.std_mul; })};
}

}  // namespace kfd
