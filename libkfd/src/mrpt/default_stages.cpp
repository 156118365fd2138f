#include "kfd/mrpt/default_stages.h"

namespace kfd {

const StageRegistry& defaultStageRegistry() {
    static const StageRegistry r =
        makeStageRegistry({registerCoreStages, registerFilterStages, registerBaselineStages});
    return r;
}

}  // namespace kfd
