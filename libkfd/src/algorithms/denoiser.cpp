#include "kfd/algorithms/denoiser.h"

#include "kfd/pipeline/error.h"

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

DenoiseVariant parseDenoiseVariant(const std::string& s) {
    if (s == "reference") return DenoiseVariant::Reference;
    if (s == "range_aware") return DenoiseVariant::RangeAware;
    if (s == "evidence") return DenoiseVariant::Evidence;
    throw ParameterError("variant", "unknown denoise variant '" + s +
                                        "' (expected reference, range_aware or evidence)");
}

void Denoiser::initialize(const Params& p) {
    if (p.filter.m_threshold < 1) throw ParameterError("m_threshold", "m_threshold must be >= 1");
    if (!(p.filter.min_object_size_m >= 0.0))
        throw ParameterError("min_object_size_m", "min_object_size_m must be >= 0");
    if (p.filter.min_points_floor < 1)
        throw ParameterError("min_points_floor", "min_points_floor must be >= 1");
    reference_.initialize(p.reference);
    range_aware_.initialize(p.range_aware);
    EvidenceFilter::Params ev = p.evidence;
    ev.min_object_size_m = p.filter.min_object_size_m;
    evidence_.initialize(ev);
    filter_ = p.filter;
    if (p.variant == DenoiseVariant::Reference) filter_.min_object_size_m = 0.0;
    params_ = p;
}

Denoiser::Result Denoiser::filter(Scan& scan, const Scan* next) {
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
    if (params_.variant == DenoiseVariant::Evidence) {
        // Marks its segments' noise flags and removes their points itself.
        const auto r = evidence_.filter(scan, clusters_, next);
        res.points_removed = unusable + r.points_removed;
        res.temporal = r.temporal;
        res.sigma = r.sigma;
        res.sigma_measured = r.sigma_measured;
        res.free_points = r.free_points;
        res.stale_references = r.stale_references;
        res.capped = r.capped;
        res.confirmed = r.confirmed;
        res.recent = r.recent;
        res.next = r.next;
    } else if (params_.variant == DenoiseVariant::Reference) {
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
    if (params_.variant != DenoiseVariant::Evidence)
        res.points_removed = unusable + filterClusters(filter_, scan, clusters_);
    res.clusters = clusters_.count();
    for (const auto f : clusters_.noise) res.noise_clusters += f;
    return res;
}

}  // namespace kfd
