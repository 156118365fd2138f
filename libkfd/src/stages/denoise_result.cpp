#include "kfd/stages/denoise_result.h"

#include <algorithm>
#include <cstdint>

#include "kfd/pipeline/stage_registry.h"

namespace kfd {

const char* toString(DenoiseVariant v) {
    switch (v) {
        case DenoiseVariant::Reference:
            return "reference";
        case DenoiseVariant::RangeAware:
            return "range_aware";
        case DenoiseVariant::Evidence:
            return "evidence";
    }
    return "unknown";
}

const char* stageName(DenoiseVariant v) {  // the core registry's `variant` choice
    const auto* o = coreStageRegistry().choice("variant")->find(toString(v));
    return o ? o->stage.c_str() : "unknown";
}

DenoiseResult startDenoising(Scan& scan, DenoiseVariant variant) {
    DenoiseResult r;
    r.variant = variant;
    r.points_in = scan.countValid();
    // Valid flags of unusable ranges cleared, branch-free (this runs over every beam of every
    // keyframe); the count from the flags after.
    const std::size_t n = std::min(scan.range.size(), scan.valid.size());
    const float* range = scan.range.data();
    std::uint8_t* valid = scan.valid.data();
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) valid[i] = isUsableRange(range[i]) ? valid[i] : 0;
    r.points_removed += r.points_in - scan.countValid();
    return r;
}

bool endDenoising(const Clusters& c, DenoiseResult& r, StageReport& report) {
    r.clusters = c.count();
    r.noise_clusters = 0;
    for (const auto f : c.noise) r.noise_clusters += f;
    report.noise = true;
    report.points_removed = r.points_removed;
    report.setDiagnostics(r);
    return true;
}

std::vector<StageColumn> denoiseColumns() {
    using R = DenoiseResult;
    return {diagnosticColumn<R>("clusters", "the clusters the denoising stage found", "%zu",
                                [](const R& r) { return r.clusters; }),
            diagnosticColumn<R>("noise_clusters", "the clusters it removed as noise", "%zu",
                                [](const R& r) { return r.noise_clusters; })};
}

}  // namespace kfd
