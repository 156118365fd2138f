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
    if (p.m_threshold < 1) throw ParameterError("m_threshold", "m_threshold must be >= 1");
    if (!(p.min_object_size_m >= 0.0))
        throw ParameterError("min_object_size_m", "min_object_size_m must be >= 0");
    if (p.min_points_floor < 1)
        throw ParameterError("min_points_floor", "min_points_floor must be >= 1");
    RingClustering::Params rp;
    rp.rings.rings = p.rings;
    rp.rings.r_max = p.ring_r_max;
    rp.angle_gap_factor = p.angle_gap_factor;
    rp.merge_distance_m = p.merge_distance_m;
    reference_.initialize(rp);
    RangeAwareClustering::Params ap;
    ap.angle_gap_factor = p.angle_gap_factor;
    ap.jump_lambda_deg = p.jump_lambda_deg;
    ap.jump_sigma_m = p.jump_sigma_m;
    range_aware_.initialize(ap);
    filter_.m_threshold = p.m_threshold;
    filter_.min_points_floor = p.min_points_floor;
    filter_.min_object_size_m = p.variant == DenoiseVariant::RangeAware ? p.min_object_size_m : 0.0;
    params_ = p;
}

Denoiser::Result Denoiser::filter(Scan& scan) {
    Result res;
    res.variant = params_.variant;
    res.points_in = scan.countValid();
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
    res.points_removed = filterClusters(filter_, scan, clusters_);
    res.clusters = clusters_.count();
    for (const auto f : clusters_.noise) res.noise_clusters += f;
    return res;
}

}  // namespace kfd
