// The core and baseline stages in one registry, for the baseline tests (which link only
// kfd::baselines, so not the MRPT layer's kfd::defaultStageRegistry()).
#pragma once

#include "kfd/baselines/stages.h"
#include "kfd/pipeline/pipeline.h"

namespace kfd::test {

inline const StageRegistry& allStages() {
    static const StageRegistry r = makeStageRegistry({registerCoreStages, registerBaselineStages});
    return r;
}

}  // namespace kfd::test
