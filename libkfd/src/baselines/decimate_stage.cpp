#include "kfd/baselines/decimate_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> DecimateStage::keys() {
    using P = Params;
    return {keys::real<P>("decimate_keep", "keep_fraction",
                          "decimate stage: share of the scans kept, evenly by count (1 = all, "
                          "0.5 = every 2nd)",
                          0, 1, true, [](P& p) -> double& { return p.keep_fraction; })};
}

}  // namespace kfd
