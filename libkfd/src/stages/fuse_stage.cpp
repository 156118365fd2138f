#include "kfd/stages/fuse_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> FuseStage::keys() {
    using P = Params;
    return {
        keys::count<P>("fuse_max_scans", "max_scans",
                       "fuse: dropped scans kept for the next keyframe (the newest); memory "
                       "fuse_max_scans x beams x 5 bytes",
                       1, 64, [](P& p) -> std::size_t& { return p.max_scans; }),
        keys::count<P>("fuse_min_agreeing", "min_agreeing",
                       "fuse: agreeing returns of dropped scans a beam needs to be fused "
                       "(at most fuse_max_scans)",
                       1, 64, [](P& p) -> std::size_t& { return p.min_agreeing; }),
        keys::real<P>("fuse_gate_sigmas", "gate_sigmas",
                      "fuse: a return agrees within fuse_gate_sigmas x sqrt(2) x sigma of the "
                      "keyframe's (sigma: range noise measured from the keyframes)",
                      0, 100, true, [](P& p) -> double& { return p.gate_sigmas; }),
        keys::real<P>("fuse_max_bias_sigmas", "max_bias_sigmas",
                      "fuse: a dropped scan whose agreeing returns are off by more than this x "
                      "sigma in the median (odometry error) takes no part",
                      0, 100, true, [](P& p) -> double& { return p.max_bias_sigmas; }),
        keys::custom<P>(
            "fuse_estimator", "estimator",
            "fuse: the estimate of a fused beam over its own and the agreeing returns",
            "median, mean",
            [](P& p, const std::string& text) { p.estimator = parseFusionEstimator(text); },
            [](const P& p) { return std::string(toString(p.estimator)); }),
        keys::real<P>("fuse_min_sigma_m", "min_sigma_m",
                      "fuse: floor of the measured range noise sigma (m)", 0, 1, true,
                      [](P& p) -> double& { return p.min_sigma_m; }),
        keys::real<P>("fuse_max_step_m", "max_step_m",
                      "fuse: dropped scans farther from the keyframe (odometry, m) are not used", 0,
                      100, true, [](P& p) -> double& { return p.max_step_m; }),
        keys::real<P>("fuse_max_step_deg", "max_step_deg",
                      "fuse: dropped scans turned more from the keyframe (deg) are not used", 0,
                      180, true, [](P& p) -> double& { return p.max_step_deg; }),
        keys::count<P>("fuse_max_span_beams", "max_span_beams",
                       "fuse: keyframe beams one segment of a dropped scan may span", 1, 64,
                       [](P& p) -> std::size_t& { return p.max_span_beams; }),
        keys::count<P>("fuse_refine_iterations", "refine_iterations",
                       "fuse: Gauss-Newton steps aligning each dropped scan to the keyframe "
                       "(point to line) before the gate; 0 = odometry only",
                       0, 20, [](P& p) -> std::size_t& { return p.refine_iterations; }),
        keys::count<P>("fuse_refine_samples", "refine_samples",
                       "fuse: returns of a dropped scan used per alignment step", 12, 4096,
                       [](P& p) -> std::size_t& { return p.refine_samples; }),
        keys::real<P>("fuse_refine_gate_m", "refine_gate_m",
                      "fuse: pairing gate of the first alignment step (m, halved after)", 0, 10,
                      true, [](P& p) -> double& { return p.refine_gate_m; })};
}

bool FuseStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    report.setDiagnostics(algo_.fuse(scan));
    return true;
}

}  // namespace kfd
