#include "kfd/baselines/dbscan.h"

#include <cmath>
#include "kfd/core/error.h"

namespace kfd {

void DbscanFilter::initialize(const Params& p) {
    if (!(p.eps_m > 0.0) || !std::isfinite(p.eps_m))
        throw ParameterError("eps_m", "dbscan_eps_m must be > 0");
    if (p.min_pts < 1) throw ParameterError("min_pts", "dbscan_min_pts must be >= 1");
    params_ = p;
}

DbscanFilter::Result DbscanFilter::filter(Scan& scan) {
    constexpr std::int32_t kUnvisited = -2, kNoise = -1;
    Result res;
    const std::size_t n = scan.range.size();
    pts_.assign(scan);
    // A valid beam without a finite range has no position: it is noise.
    for (const auto b : pts_.nonfinite) scan.valid[b] = 0;
    const std::size_t m = pts_.size();
    res.points_in = m + pts_.nonfinite.size();
    res.points_removed = pts_.nonfinite.size();
    tree_.build(pts_.x.data(), pts_.y.data(), m);
    point_label_.assign(m, kUnvisited);
    const float eps = static_cast<float>(params_.eps_m);
    std::int32_t cluster = 0;
    for (std::size_t p = 0; p < m; ++p) {
        if (point_label_[p] != kUnvisited) continue;
        tree_.radius(pts_.x[p], pts_.y[p], eps, neighbours_);
        if (neighbours_.size() < params_.min_pts) {
            point_label_[p] = kNoise;  // may still become a border point later
            continue;
        }
        point_label_[p] = cluster;
        queue_.assign(neighbours_.begin(), neighbours_.end());
        for (std::size_t k = 0; k < queue_.size(); ++k) {
            const std::uint32_t q = queue_[k];
            if (point_label_[q] == kNoise) point_label_[q] = cluster;  // border point
            if (point_label_[q] != kUnvisited) continue;
            point_label_[q] = cluster;
            tree_.radius(pts_.x[q], pts_.y[q], eps, neighbours_);
            if (neighbours_.size() >= params_.min_pts)  // core point: expand
                queue_.insert(queue_.end(), neighbours_.begin(), neighbours_.end());
        }
        ++cluster;
    }
    res.clusters = static_cast<std::size_t>(cluster);
    label_.assign(n, -1);
    for (std::size_t p = 0; p < m; ++p) {
        if (point_label_[p] >= 0) {
            label_[pts_.beam[p]] = point_label_[p];
        } else {
            scan.valid[pts_.beam[p]] = 0;
            ++res.points_removed;
        }
    }
    return res;
}

}  // namespace kfd
