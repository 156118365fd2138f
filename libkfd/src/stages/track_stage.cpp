#include "kfd/stages/track_stage.h"

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

namespace {
constexpr double kToDeg = 180.0 / kPi;
}  // namespace

std::vector<StageKey> TrackStage::keys() {
    using P = Params;
    return {
        keys::count<P>("track_samples", "max_samples",
                       "returns aligned per scan (every k-th beam, k = ceil(beams / this))", 12,
                       65536, [](P& p) -> std::size_t& { return p.max_samples; }),
        keys::count<P>("track_iterations", "max_iterations", "Gauss-Newton steps at most", 1, 100,
                       [](P& p) -> std::size_t& { return p.max_iterations; }),
        keys::real<P>("track_gate_m", "gate_m",
                      "first point-to-line pairing gate (m); halves per step", 0, 10, true,
                      [](P& p) -> double& { return p.gate_m; }),
        keys::real<P>("track_min_gate_m", "min_gate_m", "the gate's floor (m)", 0, 10, true,
                      [](P& p) -> double& { return p.min_gate_m; }),
        keys::real<P>("track_min_overlap", "min_overlap",
                      "a fit pairing fewer than this share of the sampled returns is poor", 0, 1,
                      false, [](P& p) -> double& { return p.min_overlap; }),
        keys::real<P>("track_max_spread", "max_spread",
                      "a fit whose RMS distance exceeds this share of the final gate is poor "
                      "(0.58: spread evenly over it)",
                      0, 1, true, [](P& p) -> double& { return p.max_spread; }),
        keys::real<P>("track_min_conditioning", "min_conditioning",
                      "a fit below this lambda_min / lambda_max of its translation information "
                      "is degenerate (a corridor): the odometry is kept",
                      0, 1, false, [](P& p) -> double& { return p.min_conditioning; }),
        keys::real<P>("track_link_incidence_deg", "link_incidence_deg",
                      "two neighbouring keyframe returns are one surface unless their gap needs "
                      "an incidence below this (deg)",
                      0, 90, true, [](P& p) -> double& { return p.link_incidence_deg; })};
}

bool TrackStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    report.setDiagnostics(algo_.track(scan));
    return true;
}

void TrackStage::decided(const Scan&, bool kept) {
    if (kept) algo_.accept();  // the scan as process() saw it
}

std::vector<StageColumn> TrackStage::columns() {
    using R = TrackResult;
    return {
        diagnosticColumn<R>("track",
                            "the tracker's verdict: first, tracked, degenerate or poor (the "
                            "last two keep the prior)",
                            "%s", [](const R& r) { return toString(r.verdict); }),
        diagnosticColumn<R>("track_dx", "the robot relative to its keyframe: x (m)", "%.4f",
                            [](const R& r) { return r.offset.x; }),
        diagnosticColumn<R>("track_dy", "... y (m)", "%.4f", [](const R& r) { return r.offset.y; }),
        diagnosticColumn<R>("track_dphi_deg", "... heading (deg)", "%.3f",
                            [](const R& r) { return kToDeg * r.offset.phi; }),
        diagnosticColumn<R>("track_prior_dphi_deg",
                            "the prior's heading relative to the keyframe (deg; odometry "
                            "when it had some)",
                            "%.3f", [](const R& r) { return kToDeg * r.prior.phi; }),
        diagnosticColumn<R>("track_overlap", "share of the sampled returns paired", "%.3f",
                            [](const R& r) { return static_cast<double>(r.overlap); }),
        diagnosticColumn<R>("track_rms_mm", "RMS point-to-line distance of the pairs (mm)", "%.1f",
                            [](const R& r) { return 1e3 * static_cast<double>(r.rms_m); }),
        diagnosticColumn<R>("track_conditioning",
                            "lambda_min / lambda_max of the fit's translation information", "%.3f",
                            [](const R& r) { return static_cast<double>(r.conditioning); }),
        diagnosticColumn<R>("tracked_x", "the track (laser odometry): x (m)", "%.4f",
                            [](const R& r) { return r.pose.x; }),
        diagnosticColumn<R>("tracked_y", "... y (m)", "%.4f", [](const R& r) { return r.pose.y; }),
        diagnosticColumn<R>("tracked_phi", "... heading (rad)", "%.5f",
                            [](const R& r) { return r.pose.phi; })};
}

std::vector<StageCounter> TrackStage::counters() {
    using R = TrackResult;
    return {diagnosticCounter<R>("scans_tracked", "scans aligned to their keyframe", false,
                                 [](const R& r) { return r.verdict == TrackVerdict::Tracked; }),
            diagnosticCounter<R>("scans_track_degenerate",
                                 "scans whose fit was degenerate (a corridor): prior kept", false,
                                 [](const R& r) { return r.verdict == TrackVerdict::Degenerate; }),
            diagnosticCounter<R>("scans_track_poor",
                                 "scans whose fit was poor (overlap, residuals): prior kept", false,
                                 [](const R& r) { return r.verdict == TrackVerdict::Poor; })};
}

}  // namespace kfd
