#include "kfd/stages/denoise_result.h"

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

const char* stageName(DenoiseVariant v) {
    switch (v) {
        case DenoiseVariant::Reference:
            return "denoise";
        case DenoiseVariant::RangeAware:
            return "range_aware_denoise";
        case DenoiseVariant::Evidence:
            return "evidence_denoise";
    }
    return "unknown";
}

DenoiseResult startDenoising(Scan& scan, DenoiseVariant variant) {
    DenoiseResult r;
    r.variant = variant;
    r.points_in = scan.countValid();
    for (std::size_t i = 0; i < scan.range.size(); ++i)
        if (scan.valid[i] && !isUsableRange(scan.range[i])) {
            scan.valid[i] = 0;
            ++r.points_removed;
        }
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

}  // namespace kfd
