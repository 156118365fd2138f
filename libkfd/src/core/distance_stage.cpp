#include "kfd/core/distance_stage.h"

#include "kfd/core/stage_keys.h"

namespace kfd {

std::vector<StageKey> DistanceStage::keys() {
    using P = Params;
    return {keys::real<P>("min_range", "min_range", "Algorithm 1: shortest usable range (m)", 0,
                          1000, false, [](P& p) -> double& { return p.min_range; }),
            keys::real<P>("max_range", "max_range", "Algorithm 1: longest usable range (m)", 0,
                          1000, true, [](P& p) -> double& { return p.max_range; })};
}

bool DistanceStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    const auto r = algo_.filter(scan);
    report.points_removed = r.removed_non_finite + r.removed_out_of_range;
    report.setDiagnostics(r);
    return true;
}

}  // namespace kfd
