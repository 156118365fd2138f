#include "kfd/mrpt/default_stages.h"

namespace kfd {

const StageRegistry& defaultStageRegistry() {
    static const StageRegistry r = [] {
        StageRegistry reg;
        registerCoreStages(reg);
        registerBaselineStages(reg);
        return reg;
    }();
    return r;
}

}  // namespace kfd
