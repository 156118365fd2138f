// The stage around a filter that removes beams for a reason other than noise (angle bounds, the
// robot's footprint, intensity): laser_filters' masking filters as kfd stages (std only).
#pragma once

#include "kfd/pipeline/stage.h"

namespace kfd {

/// Runs Algo::filter(scan) on every scan; never drops one. The removed beams count in
/// StageReport::points_removed, not as noise (the denoiser's scores and bounds ignore them).
template <class Algo>
class RemovalStage : public BeamFilterStage<Algo> {
  public:
    explicit RemovalStage(const typename Algo::Params& p) : BeamFilterStage<Algo>(p, false) {}
};

}  // namespace kfd
