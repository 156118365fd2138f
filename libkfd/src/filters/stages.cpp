#include "kfd/filters/stages.h"

namespace kfd {

void registerFilterStages(StageRegistry& registry) {
    registry.add<BeamCountStage>();
    registry.add<AngleBoundsStage>();
    registry.add<FootprintStage>();
    registry.add<IntensityStage>();
}

}  // namespace kfd
