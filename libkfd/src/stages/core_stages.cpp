// The core stages (the paper's and kfd's own) in a registry: registerCoreStages and
// coreStageRegistry (declared with the registry, kfd/pipeline/stage_registry.h).
#include "kfd/pipeline/stage_registry.h"
#include "kfd/stages/denoise_stage.h"
#include "kfd/stages/distance_stage.h"
#include "kfd/stages/evidence_denoise_stage.h"
#include "kfd/stages/fuse_stage.h"
#include "kfd/stages/keyframe_stage.h"
#include "kfd/stages/odometry_check_stage.h"
#include "kfd/stages/range_aware_denoise_stage.h"
#include "kfd/stages/track_stage.h"
#include "kfd/stages/view_keyframe_stage.h"

namespace kfd {

void registerCoreStages(StageRegistry& registry) {
    registry.add<DistanceStage>();           // the paper's Algorithm 1
    registry.add<KeyframeStage>();           // the paper's Sec. 3.1
    registry.add<DenoiseStage>();            // the paper's Sec. 3.2
    registry.add<ViewKeyframeStage>();       // kfd's, beyond the paper (issue 12)
    registry.add<RangeAwareDenoiseStage>();  // kfd's, beyond the paper
    registry.add<EvidenceDenoiseStage>();    // kfd's, beyond the paper (issues 16-25)
    registry.add<OdometryCheckStage>();      // kfd's, beyond the paper
    registry.add<FuseStage>();               // kfd's, beyond the paper (issue 25)
    registry.add<TrackStage>();              // kfd's, beyond the paper (issue 35)
    registry.addChoice({"selector",
                        "which keyframe stage runs: paper = keyframe (Formula 3), view = "
                        "view_keyframe (kfd's)",
                        {{"paper", KeyframeStage::kName}, {"view", ViewKeyframeStage::kName}}});
    registry.addChoice({"variant",
                        "which denoising stage runs: reference = denoise (the paper's Algorithm "
                        "2), range_aware = range_aware_denoise, evidence = evidence_denoise",
                        {{"reference", DenoiseStage::kName},
                         {"range_aware", RangeAwareDenoiseStage::kName},
                         {"evidence", EvidenceDenoiseStage::kName}}});
}

const StageRegistry& coreStageRegistry() {
    static const StageRegistry r = makeStageRegistry({registerCoreStages});
    return r;
}

}  // namespace kfd
