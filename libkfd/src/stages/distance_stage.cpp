#include "kfd/stages/distance_stage.h"

#include <cmath>
#include <limits>
#include <utility>

#include "kfd/pipeline/stage_keys.h"

namespace kfd {

std::vector<StageKey> DistanceStage::keys() {
    using P = Params;
    // max_range: a number narrows the scan's own maximum; "scan" (the default) keeps it.
    StageKey max =
        keys::real<P>("max_range", "max_range",
                      "Algorithm 1: longest usable range (m); scan = the scan's own maximum", 0,
                      1000, true, [](P& p) -> double& { return p.max_range; });
    max.range = "scan or " + max.range;
    max.set = [lo_open_set = max.set](void* p, const std::string& text) {
        if (text == "scan")
            static_cast<P*>(p)->max_range = std::numeric_limits<double>::infinity();
        else
            lo_open_set(p, text);
    };
    max.get = [](const void* p) {
        const double v = static_cast<const P*>(p)->max_range;
        return std::isinf(v) ? std::string("scan") : keys::formatReal(v);
    };
    return {keys::real<P>("min_range", "min_range",
                          "Algorithm 1: shortest usable range (m); 0 = the scan's own", 0, 1000,
                          false, [](P& p) -> double& { return p.min_range; }),
            std::move(max)};
}

bool DistanceStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    const auto r = algo_.filter(scan);
    report.points_removed = r.removed_non_finite + r.removed_out_of_range;
    report.setDiagnostics(r);
    return true;
}

std::vector<StageColumn> DistanceStage::columns() {
    using R = DistanceFilter::Result;
    return {diagnosticColumn<R>(
        "removed_range",
        "beams removed by Algorithm 1 (non-finite or outside the range "
        "limits)",
        "%zu", [](const R& r) { return r.removed_non_finite + r.removed_out_of_range; })};
}

std::vector<StageCounter> DistanceStage::counters() {
    using R = DistanceFilter::Result;
    return {diagnosticCounter<R>(
        "points_removed_range", "points out of range removed from kept scans", true,
        [](const R& r) { return r.removed_non_finite + r.removed_out_of_range; })};
}

}  // namespace kfd
