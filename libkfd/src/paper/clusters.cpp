#include "kfd/paper/clusters.h"

#include <algorithm>
#include <cmath>

namespace kfd {

void Clusters::finalize(const Scan& scan, std::vector<std::int32_t>& provisional,
                        DisjointSets& sets) {
    const std::size_t n = provisional.size();
    // Map each root to a compact label, in order of first appearance (scan order).
    std::vector<std::int32_t>& compact = compact_;
    compact.assign(sets.size(), -1);
    size.clear();
    mean_range.clear();
    label.assign(n, -1);
    std::vector<double>& sums = sums_;
    sums.clear();
    for (std::size_t i = 0; i < n; ++i) {
        if (provisional[i] < 0) continue;
        const std::uint32_t root = sets.find(static_cast<std::uint32_t>(provisional[i]));
        if (compact[root] < 0) {
            compact[root] = static_cast<std::int32_t>(size.size());
            size.push_back(0);
            sums.push_back(0.0);
        }
        const std::int32_t l = compact[root];
        label[i] = l;
        ++size[l];
        sums[l] += scan.range[i];
    }
    mean_range.resize(size.size());
    for (std::size_t l = 0; l < size.size(); ++l)
        mean_range[l] = static_cast<float>(sums[l] / static_cast<double>(size[l]));
    noise.assign(size.size(), 0);
}

std::size_t minClusterPoints(const ClusterFilterParams& p, double mean_range, double resolution) {
    // Negated tests: a NaN range or resolution falls back to m_threshold (never cast NaN).
    if (!(p.min_object_size_m > 0.0) || !(resolution > 0.0) || !(mean_range > 0.0))
        return p.m_threshold;
    const double beams = std::ceil(p.min_object_size_m / (mean_range * resolution));
    if (!std::isfinite(beams)) return p.m_threshold;
    const double lo = static_cast<double>(std::min(p.min_points_floor, p.m_threshold));
    const double hi = static_cast<double>(p.m_threshold);
    return static_cast<std::size_t>(std::clamp(beams, lo, hi));
}

std::size_t filterClusters(const ClusterFilterParams& p, Scan& scan, Clusters& c) {
    const double res = scan.geometry.resolution();
    std::size_t removed = 0;
    for (std::size_t l = 0; l < c.count(); ++l)
        c.noise[l] = c.size[l] < minClusterPoints(p, c.mean_range[l], res) ? 1 : 0;
    for (std::size_t i = 0; i < c.label.size(); ++i) {
        const std::int32_t l = c.label[i];
        if (l >= 0 && c.noise[l]) {
            scan.valid[i] = 0;
            ++removed;
        }
    }
    return removed;
}

}  // namespace kfd
