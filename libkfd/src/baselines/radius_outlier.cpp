#include "kfd/baselines/radius_outlier.h"

#include <cmath>
#include "kfd/pipeline/error.h"

namespace kfd {

void RadiusOutlierFilter::initialize(const Params& p) {
    if (!(p.radius_m > 0.0) || !std::isfinite(p.radius_m))
        throw ParameterError("radius_m", "radius_m must be finite and > 0");
    if (p.min_neighbors < 1)
        throw ParameterError("min_neighbors", "radius_min_neighbors must be >= 1");
    params_ = p;
}

RadiusOutlierFilter::Result RadiusOutlierFilter::filter(Scan& scan) {
    Result res;
    pts_.assign(scan);
    noise_ = pts_.nonfinite;  // no position, no neighbours
    const std::size_t m = pts_.size();
    res.points_in = m + pts_.nonfinite.size();
    tree_.build(pts_.x.data(), pts_.y.data(), m);
    const float r = static_cast<float>(params_.radius_m);
    for (std::size_t p = 0; p < m; ++p) {
        // Capped at min_neighbors + 1 (p itself and min_neighbors others): enough to decide.
        tree_.radius(pts_.x[p], pts_.y[p], r, neighbours_, params_.min_neighbors + 1);
        // The answer always holds p itself (distance 0); the others are its neighbours.
        if (neighbours_.size() - 1 < params_.min_neighbors) noise_.push_back(pts_.beam[p]);
    }
    for (const auto b : noise_) scan.valid[b] = 0;
    res.points_removed = noise_.size();
    return res;
}

}  // namespace kfd
