// Every core stage (the paper's and kfd's own) in one include, for code that configures a
// pipeline by stage class: p.get<kfd::ViewKeyframeStage>(), report.find<kfd::DenoiseResult>().
#pragma once

#include "kfd/stages/denoise_result.h"
#include "kfd/stages/denoise_stage.h"
#include "kfd/stages/distance_stage.h"
#include "kfd/stages/evidence_denoise_stage.h"
#include "kfd/stages/fuse_stage.h"
#include "kfd/stages/keyframe_stage.h"
#include "kfd/stages/odometry_check_stage.h"
#include "kfd/stages/range_aware_denoise_stage.h"
#include "kfd/stages/view_keyframe_stage.h"
