#include "kfd/baselines/shadow_filter.h"

#include <algorithm>
#include <cmath>

namespace kfd {

void ShadowFilter::initialize(const Params& p) {
    if (!(p.min_angle_deg >= 0.0 && p.min_angle_deg < p.max_angle_deg && p.max_angle_deg <= 180.0))
        throw ParameterError("shadow_min_angle_deg",
                             "shadow angles must satisfy 0 <= min_angle < max_angle <= 180");
    if (p.window < 1 || p.window > 64)
        throw ParameterError("shadow_window", "shadow_window must be in [1, 64]");
    if (p.neighbors > 1000)
        throw ParameterError("shadow_neighbors", "shadow_neighbors must be in [0, 1000]");
    params_ = p;
}

ShadowFilter::Result ShadowFilter::filter(Scan& scan) {
    Result res;
    const std::size_t n = scan.range.size();
    res.points_in = scan.countValid();
    remove_.assign(n, 0);
    const double res_ang = scan.geometry.resolution();
    const double lo = params_.min_angle_deg * kPi / 180.0, hi = params_.max_angle_deg * kPi / 180.0;
    const std::size_t w = params_.window, nb = params_.neighbors;
    for (std::size_t i = 0; i < n; ++i) {
        if (!scan.valid[i] || !std::isfinite(scan.range[i])) continue;
        const double ri = scan.range[i];
        const std::size_t j0 = i > w ? i - w : 0, j1 = std::min(n - 1, i + w);
        bool shadow = false;
        for (std::size_t j = j0; j <= j1 && !shadow; ++j) {
            if (j == i || !scan.valid[j] || !std::isfinite(scan.range[j])) continue;
            const double a = static_cast<double>(j > i ? j - i : i - j) * res_ang;
            const double rj = scan.range[j];
            const double angle = std::abs(std::atan2(rj * std::sin(a), ri - rj * std::cos(a)));
            shadow = angle < lo || angle > hi;
        }
        if (!shadow) continue;
        ++res.shadow_tests;
        const std::size_t k0 = i > nb ? i - nb : 0, k1 = std::min(n - 1, i + nb);
        for (std::size_t k = k0; k <= k1; ++k)
            if (scan.valid[k] && scan.range[k] > ri) remove_[k] = 1;
        if (params_.remove_start) remove_[i] = 1;
    }
    for (std::size_t i = 0; i < n; ++i)
        if (remove_[i] && scan.valid[i]) {
            scan.valid[i] = 0;
            ++res.points_removed;
        }
    return res;
}

}  // namespace kfd
