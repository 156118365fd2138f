#include "kfd/baselines/stages.h"

namespace kfd {

void registerBaselineStages(StageRegistry& registry) {
    registry.add<MotionStage>();
    registry.add<DbscanStage>();
    registry.add<RadiusStage>();
    registry.add<SorStage>();
    registry.add<ShadowStage>();
    registry.add<SpeckleStage>();
    registry.add<DecimateStage>();
}

}  // namespace kfd
