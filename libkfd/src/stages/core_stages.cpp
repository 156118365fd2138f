// The core stages (the paper's and kfd's own) in a registry: registerCoreStages and
// coreStageRegistry (declared with the registry, kfd/pipeline/stage_registry.h).
#include "kfd/pipeline/stage_registry.h"
#include "kfd/stages/denoise_stage.h"
#include "kfd/stages/distance_stage.h"
#include "kfd/stages/fuse_stage.h"
#include "kfd/stages/keyframe_stage.h"
#include "kfd/stages/odometry_check_stage.h"

namespace kfd {

void registerCoreStages(StageRegistry& registry) {
    registry.add<DistanceStage>();
    registry.add<KeyframeStage>();
    registry.add<DenoiseStage>();
    registry.add<OdometryCheckStage>();  // kfd's, beyond the paper
    registry.add<FuseStage>();           // kfd's, beyond the paper (issue 25)
}

const StageRegistry& coreStageRegistry() {
    static const StageRegistry r = makeStageRegistry({registerCoreStages});
    return r;
}

}  // namespace kfd
