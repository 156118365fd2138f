#include "kfd/stages/odometry_check_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> OdometryCheckStage::keys() {
    using P = Params;
    return {keys::real<P>("frozen_changed_fraction", "frozen_changed_fraction",
                          "odometry_check: odometry standing still is frozen once this share "
                          "of the beams changed",
                          0, 1, true, [](P& p) -> double& { return p.frozen_changed_fraction; }),
            keys::real<P>("jump_margin", "jump_margin",
                          "odometry_check: a step is a jump when standing still explains this "
                          "share of the beams more",
                          0, 1, true, [](P& p) -> double& { return p.jump_margin; })};
}

bool OdometryCheckStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    report.setDiagnostics(algo_.check(scan));
    return true;
}

std::vector<StageColumn> OdometryCheckStage::columns() {
    using R = OdometryCheck::Result;
    return {diagnosticColumn<R>("odometry_check",
                                "the verdict: none (no odometry), ok, frozen or jump (withheld "
                                "from the stages)",
                                "%s", [](const R& r) { return toString(r.verdict); })};
}

std::vector<StageCounter> OdometryCheckStage::counters() {
    using R = OdometryCheck::Result;
    return {diagnosticCounter<R>("scans_odometry_frozen",
                                 "scans whose odometry stood still as they changed", false,
                                 [](const R& r) { return r.verdict == OdometryVerdict::Frozen; }),
            diagnosticCounter<R>("scans_odometry_jump",
                                 "scans whose odometry jumped where they did not", false,
                                 [](const R& r) { return r.verdict == OdometryVerdict::Jump; })};
}

}  // namespace kfd
