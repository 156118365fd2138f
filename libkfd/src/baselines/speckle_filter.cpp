#include "kfd/baselines/speckle_filter.h"

#include <algorithm>
#include <cmath>

namespace kfd {

void SpeckleFilter::initialize(const Params& p) {
    if (!(p.max_range >= 0.0 && std::isfinite(p.max_range)))
        throw ParameterError("max_range", "speckle_max_range must be a finite range >= 0");
    if (!(p.max_range_difference >= 0.0 && std::isfinite(p.max_range_difference)))
        throw ParameterError("max_range_difference",
                             "speckle_max_range_difference must be a finite distance >= 0");
    if (p.window < 1 || p.window > 100)
        throw ParameterError("window", "speckle_window must be in [1, 100]");
    params_ = p;
}

bool SpeckleFilter::distanceRunPasses(const Scan& scan, std::size_t i) const {
    if (!scan.valid[i]) return false;
    const double r = scan.range[i];
    for (std::size_t k = 1; k < params_.window && i + k < scan.size(); ++k)
        if (!scan.valid[i + k] || std::abs(scan.range[i + k] - r) > params_.max_range_difference)
            return false;
    return true;
}

bool SpeckleFilter::radiusRunPasses(const Scan& scan, std::size_t i) const {
    if (!scan.valid[i]) return false;
    const long w = static_cast<long>(params_.window), n = static_cast<long>(scan.size());
    const double r1 = scan.range[i], res = scan.geometry.resolution();
    long found = 0;
    for (long y = -w; y <= w && found < w; ++y) {
        const long j = static_cast<long>(i) + y;
        if (j < 0 || j >= n || y == 0 || !scan.valid[j]) continue;
        const double r2 = scan.range[j];
        const double d2 =
            r1 * r1 + r2 * r2 - 2.0 * r1 * r2 * std::cos(static_cast<double>(y) * res);
        if (std::sqrt(std::max(0.0, d2)) <= params_.max_range_difference) ++found;
    }
    return found >= w;
}

SpeckleFilter::Result SpeckleFilter::filter(Scan& scan) {
    Result res;
    const std::size_t n = scan.size(), w = params_.window;
    res.points_in = scan.countValid();
    if (n <= w + 1) return res;
    keep_.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i)
        keep_[i] = scan.valid[i] && scan.range[i] > params_.max_range;
    for (std::size_t i = 0; i + w <= n; ++i) {
        const bool pass = params_.radius ? radiusRunPasses(scan, i) : distanceRunPasses(scan, i);
        if (!pass) continue;
        for (std::size_t k = 0; k < w; ++k) keep_[i + k] = 1;
    }
    for (std::size_t i = 0; i < n; ++i)
        if (scan.valid[i] && !keep_[i]) {
            scan.valid[i] = 0;
            ++res.points_removed;
        }
    return res;
}

}  // namespace kfd
