#include "kfd/core/denoiser.h"

#include "kfd/core/error.h"

namespace kfd {

const char* toString(DenoiseVariant v) {
    return v == DenoiseVariant::Reference ? "reference" : "range_aware";
}

DenoiseVariant parseDenoiseVariant(const std::string& s) {
    if (s == "reference") return DenoiseVariant::Reference;
    if (s == "range_aware") return DenoiseVariant::RangeAware;
    throw ParameterError("variant",
                         "unknown denoise variant '" + s + "' (expected reference or range_aware)");
}

void Denoiser::initialize(const Params& p) {
    if (p.filter.m_threshold < 1) throw ParameterError("m_threshold", "m_threshold must be >= 1");
    if (!(p.filter.min_object_size_m >= 0.0))
        throw ParameterError("min_object_size_m", "min_object_size_m must be >= 0");
    if (p.filter.min_points_floor < 1)
        throw ParameterError("min_points_floor", "min_points_floor must be >= 1");
    reference_.initialize(p.reference);
    range_aware_.initialize(p.range_aware);
    filter_ = p.filter;
    if (p.variant != DenoiseVariant::RangeAware) filter_.min_object_size_m = 0.0;
    params_ = p;
}

Denoiser::Result Denoiser::filter(Scan& scan) {
    Result res;
    res.variant = params_.variant;
    res.points_in = scan.countValid();
    // A beam without a usable range (NaN, +-inf, negative, above kMaxScanRangeM) has no place in
    // a cluster: removed first (normally the distance stage has already done so).
    std::size_t unusable = 0;
    for (std::size_t i = 0; i < scan.range.size(); ++i)
        if (scan.valid[i] && !isUsableRange(scan.range[i])) {
            scan.valid[i] = 0;
            ++unusable;
        }
    if (params_.variant == DenoiseVariant::Reference) {
        const auto r = reference_.cluster(scan, clusters_);
        res.blocks = r.blocks;
        res.merges = r.merges;
        res.r_max = r.r_max;
        res.theta_threshold = r.theta_threshold;
    } else {
        const auto r = range_aware_.cluster(scan, clusters_);
        res.merges = r.merges;
        res.theta_threshold = r.theta_threshold;
    }
    res.points_removed = unusable + filterClusters(filter_, scan, clusters_);
    res.clusters = clusters_.count();
    for (const auto f : clusters_.noise) res.noise_clusters += f;
    return res;
}

}  // namespace kfd
