#include "kfd/baselines/dbscan.h"

#include <algorithm>
#include <cmath>

#include "kfd/pipeline/error.h"

namespace kfd {

void DbscanFilter::initialize(const Params& p) {
    if (!(p.eps_m >= kMinEpsM) || !std::isfinite(p.eps_m))
        throw ParameterError("eps_m", "dbscan_eps_m must be finite and >= 1e-6 m");
    if (p.min_pts < 1) throw ParameterError("min_pts", "dbscan_min_pts must be >= 1");
    params_ = p;
}

DbscanFilter::Result DbscanFilter::filter(Scan& scan) {
    Result res;
    const std::size_t n = scan.range.size();
    pts_.assign(scan);
    // A valid beam without a usable range has no position: it is noise.
    for (const auto b : pts_.nonfinite) scan.valid[b] = 0;
    const std::size_t m = pts_.size();
    res.points_in = m + pts_.nonfinite.size();
    res.points_removed = pts_.nonfinite.size();
    tree_.build(pts_.x.data(), pts_.y.data(), m);
    const float eps = static_cast<float>(params_.eps_m);
    stats_ = Stats{};
    markCorePoints(eps);
    binInCells();
    joinWithinCells();
    joinAcrossCells(eps * eps);  // the tree's inclusive float test: dx*dx + dy*dy <= eps2
    res.clusters = numberClusters(eps);
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

// 1. Core points: min_pts points (itself included) within eps. Each query stops at min_pts.
void DbscanFilter::markCorePoints(float eps) {
    const std::size_t m = pts_.size();
    core_.assign(m, 0);
    for (std::size_t p = 0; p < m; ++p) {
        tree_.radius(pts_.x[p], pts_.y[p], eps, neighbours_, params_.min_pts);
        stats_.neighbours_visited += neighbours_.size();
        core_[p] = neighbours_.size() >= params_.min_pts ? 1 : 0;
    }
}

// 2. Clusters = connected components of the core points (edges: distance <= eps). Points are
// binned in square cells of side < eps / sqrt(2): two core points in one cell are always
// connected, and a point within eps of another lies at most 2 cells away. Cells are runs of
// `order_` sorted by cell key; pairs of cells are tested with an early exit.
void DbscanFilter::binInCells() {
    const std::size_t m = pts_.size();
    const double side = params_.eps_m / std::sqrt(2.0) * (1.0 - 1e-4);
    cell_.resize(m);
    order_.resize(m);
    for (std::size_t p = 0; p < m; ++p) {
        // |x|, |y| <= kMaxScanRangeM (ScanPoints) and side >= 7e-7 m: |x / side| < 1.5e10.
        const auto cx = static_cast<std::int64_t>(std::floor(pts_.x[p] / side));
        const auto cy = static_cast<std::int64_t>(std::floor(pts_.y[p] / side));
        cell_[p] = Cell{cx, cy};
        order_[p] = static_cast<std::uint32_t>(p);
    }
    auto less = [&](std::uint32_t a, std::uint32_t b) {
        return cell_[a].x != cell_[b].x   ? cell_[a].x < cell_[b].x
               : cell_[a].y != cell_[b].y ? cell_[a].y < cell_[b].y
                                          : a < b;
    };
    std::sort(order_.begin(), order_.end(), less);
    runs_.clear();  // [begin, end) of each cell in order_
    for (std::size_t k = 0; k < m; ++k)
        if (k == 0 || cell_[order_[k]].x != cell_[order_[k - 1]].x ||
            cell_[order_[k]].y != cell_[order_[k - 1]].y)
            runs_.push_back(Run{static_cast<std::uint32_t>(k), 0});
    for (std::size_t c = 0; c < runs_.size(); ++c)
        runs_[c].end = c + 1 < runs_.size() ? runs_[c + 1].begin : static_cast<std::uint32_t>(m);
}

// One cell: its core points are one component.
void DbscanFilter::joinWithinCells() {
    sets_.clear();
    for (std::size_t p = 0; p < pts_.size(); ++p) sets_.add();
    for (const auto& run : runs_) {
        std::int64_t first = -1;
        for (std::uint32_t k = run.begin; k < run.end; ++k) {
            const std::uint32_t p = order_[k];
            if (!core_[p]) continue;
            if (first < 0)
                first = p;
            else
                sets_.unite(static_cast<std::uint32_t>(first), p);
        }
    }
}

// The run of cell (cx, cy), or nullptr when no point lies there.
const DbscanFilter::Run* DbscanFilter::findRun(std::int64_t cx, std::int64_t cy) const {
    auto it = std::lower_bound(runs_.begin(), runs_.end(), Cell{cx, cy},
                               [&](const Run& r, const Cell& c) {
                                   const Cell& rc = cell_[order_[r.begin]];
                                   return rc.x != c.x ? rc.x < c.x : rc.y < c.y;
                               });
    if (it == runs_.end()) return nullptr;
    const Cell& rc = cell_[order_[it->begin]];
    return rc.x == cx && rc.y == cy ? &*it : nullptr;
}

// Cells up to 2 apart: joined by the first pair of their core points within eps.
void DbscanFilter::joinAcrossCells(float eps2) {
    for (const auto& a : runs_) {
        const Cell ca = cell_[order_[a.begin]];
        for (std::int64_t dx = -2; dx <= 2; ++dx) {
            for (std::int64_t dy = -2; dy <= 2; ++dy) {
                if (dx < 0 || (dx == 0 && dy <= 0)) continue;  // each pair of cells once
                const Run* b = findRun(ca.x + dx, ca.y + dy);
                if (!b) continue;
                bool joined = false;
                for (std::uint32_t i = a.begin; i < a.end && !joined; ++i) {
                    const std::uint32_t p = order_[i];
                    if (!core_[p]) continue;
                    for (std::uint32_t j = b->begin; j < b->end; ++j) {
                        const std::uint32_t q = order_[j];
                        if (!core_[q]) continue;
                        if (sets_.find(p) == sets_.find(q)) {  // already one component
                            joined = true;
                            break;
                        }
                        ++stats_.pairs_tested;
                        const float ddx = pts_.x[p] - pts_.x[q], ddy = pts_.y[p] - pts_.y[q];
                        if (ddx * ddx + ddy * ddy <= eps2) {
                            sets_.unite(p, q);
                            joined = true;
                            break;
                        }
                    }
                }
            }
        }
    }
}

// 3. Numbering as Ester's sequential algorithm does: by the smallest core point of each
// cluster. A border point (not core, a core point within eps) takes the smallest cluster
// number among its core neighbours, the one whose expansion would have reached it first.
// Returns the number of clusters.
std::size_t DbscanFilter::numberClusters(float eps) {
    constexpr std::int32_t kNone = -1;
    const std::size_t m = pts_.size();
    point_label_.assign(m, kNone);
    root_label_.assign(m, kNone);
    std::int32_t cluster = 0;
    for (std::size_t p = 0; p < m; ++p) {
        if (!core_[p]) continue;
        const std::uint32_t r = sets_.find(static_cast<std::uint32_t>(p));
        if (root_label_[r] == kNone) root_label_[r] = cluster++;
        point_label_[p] = root_label_[r];
    }
    for (std::size_t p = 0; p < m; ++p) {
        if (core_[p]) continue;
        // Not core: fewer than min_pts points within eps, so this full query is short.
        tree_.radius(pts_.x[p], pts_.y[p], eps, neighbours_);
        stats_.neighbours_visited += neighbours_.size();
        for (const auto q : neighbours_)
            if (core_[q]) {
                const std::int32_t l = root_label_[sets_.find(q)];
                if (point_label_[p] == kNone || l < point_label_[p]) point_label_[p] = l;
            }
    }
    return static_cast<std::size_t>(cluster);
}

}  // namespace kfd
