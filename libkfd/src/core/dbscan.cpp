#include "kfd/core/dbscan.h"

#include <cmath>
#include <stdexcept>

namespace kfd {

void DbscanFilter::initialize(const Params& p) {
    if (!(p.eps_m > 0.0) || !std::isfinite(p.eps_m))
        throw std::invalid_argument("dbscan_eps_m must be > 0");
    if (p.min_pts < 1) throw std::invalid_argument("dbscan_min_pts must be >= 1");
    params_ = p;
}

DbscanFilter::Result DbscanFilter::filter(Scan& scan) {
    constexpr std::int32_t kUnvisited = -2, kNoise = -1;
    Result res;
    const std::size_t n = scan.range.size();
    x_.clear();
    y_.clear();
    beam_.clear();
    for (std::size_t i = 0; i < n; ++i) {
        if (!scan.valid[i]) continue;
        const double a = scan.geometry.angle(i);
        x_.push_back(static_cast<float>(scan.range[i] * std::cos(a)));
        y_.push_back(static_cast<float>(scan.range[i] * std::sin(a)));
        beam_.push_back(static_cast<std::uint32_t>(i));
    }
    const std::size_t m = x_.size();
    res.points_in = m;
    tree_.build(x_.data(), y_.data(), m);
    point_label_.assign(m, kUnvisited);
    const float eps = static_cast<float>(params_.eps_m);
    std::int32_t cluster = 0;
    for (std::size_t p = 0; p < m; ++p) {
        if (point_label_[p] != kUnvisited) continue;
        tree_.radius(x_[p], y_[p], eps, neighbours_);
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
            tree_.radius(x_[q], y_[q], eps, neighbours_);
            if (neighbours_.size() >= params_.min_pts)  // core point: expand
                queue_.insert(queue_.end(), neighbours_.begin(), neighbours_.end());
        }
        ++cluster;
    }
    res.clusters = static_cast<std::size_t>(cluster);
    label_.assign(n, -1);
    for (std::size_t p = 0; p < m; ++p) {
        if (point_label_[p] >= 0) {
            label_[beam_[p]] = point_label_[p];
        } else {
            scan.valid[beam_[p]] = 0;
            ++res.points_removed;
        }
    }
    return res;
}

}  // namespace kfd
