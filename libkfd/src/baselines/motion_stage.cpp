#include "kfd/baselines/motion_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> MotionStage::keys() {
    using P = Params;
    return {keys::real<P>("motion_distance_m", "max_distance_m",
                          "motion stage: keep after D metres of odometry (0 = off)", 0, 1e6, false,
                          [](P& p) -> double& { return p.max_distance_m; }),
            keys::real<P>("motion_angle_deg", "max_angle_deg",
                          "motion stage: keep after A degrees of odometry (0 = off)", 0, 360, false,
                          [](P& p) -> double& { return p.max_angle_deg; }),
            keys::real<P>("motion_interval_s", "max_interval_s",
                          "motion stage: keep after T seconds (0 = off)", 0, 1e9, false,
                          [](P& p) -> double& { return p.max_interval_s; })};
}

bool MotionStage::process(Scan& scan, StageReport&, const ScanReport&) {
    return algo_.keep(scan.timestamp, scan.odometry);
}

}  // namespace kfd
