#include "kfd/paper/rings.h"

#include <algorithm>
#include <cmath>
#include "kfd/pipeline/error.h"

namespace kfd {

void RingPartition::initialize(const Params& p) {
    if (p.rings < 1 || p.rings > 254) throw ParameterError("rings", "rings must be in [1, 254]");
    if (!(p.r_max >= 0.0) || !std::isfinite(p.r_max))
        throw ParameterError("r_max", "ring_r_max must be >= 0 (0 = farthest point)");
    params_ = p;
}

double RingPartition::outerRadius(std::size_t i, double r_max) const {
    return std::sqrt(static_cast<double>(i) / static_cast<double>(params_.rings)) * r_max;
}

std::size_t RingPartition::ringOf(double r, double r_max) const {
    const std::size_t t = params_.rings;
    if (r_max <= 0.0) return 0;
    const double q = static_cast<double>(t) * (r * r) / (r_max * r_max);
    const double i = std::ceil(q);  // 1-based ring
    if (!(i >= 1.0)) return 0;
    if (i >= static_cast<double>(t)) return t - 1;
    return static_cast<std::size_t>(i) - 1;
}

double RingPartition::compute(const Scan& scan, std::vector<std::uint8_t>& ring_of_beam) const {
    const std::size_t n = scan.range.size();
    ring_of_beam.assign(n, kNoRing);
    double r_max = params_.r_max;
    if (r_max <= 0.0) {
        for (std::size_t i = 0; i < n; ++i)
            if (scan.valid[i]) r_max = std::max(r_max, static_cast<double>(scan.range[i]));
    }
    for (std::size_t i = 0; i < n; ++i)
        if (scan.valid[i])
            ring_of_beam[i] = static_cast<std::uint8_t>(ringOf(scan.range[i], r_max));
    return r_max;
}

}  // namespace kfd
