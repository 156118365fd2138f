#include "kfd/filters/intensity_filter.h"

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/stage_keys.h"

namespace kfd {

void IntensityFilter::initialize(const Params& p) {
    if (!(p.lower <= p.upper))
        throw ParameterError("lower", "intensity: need lower (" + keys::formatReal(p.lower) +
                                          ") <= upper (" + keys::formatReal(p.upper) + ")");
    params_ = p;
}

IntensityFilter::Result IntensityFilter::filter(Scan& scan) const {
    Result r;
    const bool has = scan.intensity.size() == scan.size() && scan.size() > 0;
    r.no_intensity = has ? 0 : 1;
    for (std::size_t i = 0; i < scan.size(); ++i) {
        if (!scan.valid[i]) continue;
        ++r.points_in;
        if (!has) continue;
        const double v = scan.intensity[i];
        if (v < params_.lower || v > params_.upper) {
            scan.valid[i] = 0;
            ++r.points_removed;
        }
    }
    return r;
}

std::vector<StageKey> IntensityStage::keys() {
    using P = Params;
    return {keys::real<P>("intensity_lower", "lower",
                          "intensity: weaker returns are removed (driver's units)", -1e9, 1e9,
                          false, [](P& p) -> double& { return p.lower; }),
            keys::real<P>("intensity_upper", "upper",
                          "intensity: stronger returns are removed (driver's units)", -1e9, 1e9,
                          false, [](P& p) -> double& { return p.upper; })};
}

std::vector<StageColumn> IntensityStage::columns() {
    using R = IntensityFilter::Result;
    return {diagnosticColumn<R>("removed_intensity", "returns removed by the intensity threshold",
                                "%zu", [](const R& r) { return r.points_removed; })};
}

std::vector<StageCounter> IntensityStage::counters() {
    using R = IntensityFilter::Result;
    return {diagnosticCounter<R>("points_removed_intensity",
                                 "returns outside the intensity bounds removed from kept scans",
                                 true, [](const R& r) { return r.points_removed; }),
            diagnosticCounter<R>("scans_without_intensity",
                                 "scans the intensity stage left as they were (no intensities)",
                                 false, [](const R& r) { return r.no_intensity; })};
}

}  // namespace kfd
