#include "kfd/stages/view_keyframe_stage.h"

#include <string>

#include "guard_keys.h"
#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> ViewKeyframeStage::keys() {
    using P = Params;
    using V = ViewSelector::Params;
    auto viewReal = [](const char* name, const char* help, double lo, double hi, bool lo_open,
                       double V::*member) {
        std::string field = name;  // the Params field: the key without "view_"
        if (field.rfind("view_", 0) == 0) field = field.substr(5);
        return keys::real<P>(name, field, help, lo, hi, lo_open,
                             [member](P& p) -> double& { return p.view.*member; });
    };
    std::vector<StageKey> k = {
        keys::count<P>("view_samples", "max_samples",
                       "beams sampled per scan (every k-th, k = ceil(beams / this))", 2, 65536,
                       [](P& p) -> std::size_t& { return p.view.max_samples; }),
        viewReal("view_tolerance_m", "displacement unit a of a point at range 0 (m)", 0, 1e3, true,
                 &V::tolerance_m),
        viewReal("view_tolerance_deg", "the unit grows by r tan(b) at range r (b, deg)", 0, 89.9,
                 false, &V::tolerance_deg),
        viewReal("max_view_change",
                 "odometry: keyframe at this RMS point displacement (units a + r tan b)", 0, 1e3,
                 true, &V::max_view_change),
        viewReal("change_tolerance_m", "laser only: a range changed beyond this (m) ...", 0, 1e3,
                 false, &V::change_tolerance_m),
        viewReal("change_tolerance_ratio", "laser only: ... plus this share of the range", 0, 10,
                 false, &V::change_tolerance_ratio),
        viewReal("max_changed_fraction",
                 "laser only: keyframe when this share of the returns "
                 "changed",
                 0, 1, true, &V::max_changed_fraction),
        viewReal("degeneracy_ratio",
                 "corridor switch: degenerate below lambda_min/lambda_max of the normals "
                 "(0 = off)",
                 0, 1, false, &V::degeneracy_ratio),
        viewReal("corridor_translation_m",
                 "corridor switch, odometry: keyframe after this travel (m)", 0, 1e6, true,
                 &V::corridor_translation_m),
        viewReal("corridor_rotation_deg",
                 "corridor switch, odometry: keyframe after this turn (deg)", 0, 360, true,
                 &V::corridor_rotation_deg),
        viewReal("corridor_interval_s", "corridor switch, laser only: keyframe after this time (s)",
                 0, 1e6, true, &V::corridor_interval_s),
        viewReal("max_track_disagreement",
                 "with the track stage: keyframe when the tracked motion and the odometry "
                 "differ by this view change (0 = off)",
                 0, 1e3, false, &V::max_track_disagreement)};
    for (auto& g : guardKeys<P>()) k.push_back(std::move(g));
    return k;
}

bool ViewKeyframeStage::process(Scan& scan, StageReport& report, const ScanReport& chain) {
    const KeyframeDecision d = algo_.filter(scan, chain.find<TrackResult>());
    report.setDiagnostics(d);
    return d.keyframe;
}

std::vector<StageColumn> ViewKeyframeStage::columns() {
    using D = KeyframeDecision;
    return {diagnosticColumn<D>("references", "keyframes compared against (1 once there is one)",
                                "%zu", [](const D& d) { return d.references; }),
            diagnosticColumn<D>("view_change",
                                "RMS displacement of the view since the keyframe, in tolerances",
                                "%.4f", [](const D& d) { return d.view_change; }),
            diagnosticColumn<D>("changed_fraction",
                                "laser only: the share of common returns that changed", "%.4f",
                                [](const D& d) { return d.changed_fraction; }),
            diagnosticColumn<D>("degeneracy",
                                "lambda_min / lambda_max of the normals' information (1: none)",
                                "%.4f", [](const D& d) { return d.degeneracy; }),
            diagnosticColumn<D>("corridor", "1: the corridor switch found the scan degenerate",
                                "%d", [](const D& d) { return d.corridor ? 1 : 0; })};
}

std::vector<StageCounter> ViewKeyframeStage::counters() {
    using D = KeyframeDecision;
    return {diagnosticCounter<D>("scans_corridor", "scans the corridor switch found degenerate",
                                 false, [](const D& d) { return d.corridor; }),
            diagnosticCounter<D>("keyframes_corridor",
                                 "keyframes the corridor switch made (odometry or time)", false,
                                 [](const D& d) { return d.reason == KeyframeReason::Corridor; })};
}

}  // namespace kfd
