#include "kfd/stages/keyframe_stage.h"

#include "guard_keys.h"
#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> KeyframeStage::keys() {
    using P = Params;
    std::vector<StageKey> k = {
        keys::count<P>("bins", "bins", "Sec. 3.1.2: histogram columns n", 2, 4096,
                       [](P& p) -> std::size_t& { return p.bins; }),
        keys::count<P>("window", "window", "Sec. 3.1.4: sliding window m (keyframes compared)", 1,
                       1024, [](P& p) -> std::size_t& { return p.window; }),
        keys::real<P>("p_pair", "p_pair",
                      "Formula 3: pairwise similarity threshold; P_threshold = P_pair^m", 0, 1,
                      true, [](P& p) -> double& { return p.p_pair; })};
    for (auto& g : guardKeys<P>()) k.push_back(std::move(g));
    return k;
}

bool KeyframeStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    const KeyframeDecision d = algo_.filter(scan);
    report.setDiagnostics(d);
    return d.keyframe;
}

std::vector<StageColumn> KeyframeStage::columns() {
    using D = KeyframeDecision;
    return {diagnosticColumn<D>("p_common",
                                "P_common, the product of the clamped correlations (Formula 3)",
                                "%.6f", [](const D& d) { return d.p_common; }),
            diagnosticColumn<D>("p_threshold", "P_pair^k, the threshold P_common is held to",
                                "%.6f", [](const D& d) { return d.p_threshold; }),
            diagnosticColumn<D>("references", "k, the keyframes compared against (<= window)",
                                "%zu", [](const D& d) { return d.references; })};
}

}  // namespace kfd
