// Cluster bookkeeping shared by the clustering variants, and the cluster filter (Sec. 3.2.4).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/pipeline/scan.h"

namespace kfd {

/// Union-find over provisional cluster ids (path halving, union by index). Reused across scans.
class DisjointSets {
  public:
    void clear() { parent_.clear(); }
    std::uint32_t add() {
        parent_.push_back(static_cast<std::uint32_t>(parent_.size()));
        return parent_.back();
    }
    std::uint32_t find(std::uint32_t a) {
        while (parent_[a] != a) {
            parent_[a] = parent_[parent_[a]];
            a = parent_[a];
        }
        return a;
    }
    /// Returns true when a and b were in different sets.
    bool unite(std::uint32_t a, std::uint32_t b) {
        a = find(a);
        b = find(b);
        if (a == b) return false;
        if (a < b)
            parent_[b] = a;
        else
            parent_[a] = b;
        return true;
    }
    std::size_t size() const { return parent_.size(); }

  private:
    std::vector<std::uint32_t> parent_;
};

/// The clusters of one scan: a label per beam (-1 = invalid beam) and per-cluster statistics.
struct Clusters {
    std::vector<std::int32_t> label;  // per beam, 0..count-1, or -1
    std::vector<std::uint32_t> size;  // points per cluster
    std::vector<float> mean_range;    // m, per cluster
    std::vector<std::uint8_t> noise;  // 1 = removed by the cluster filter
    std::size_t count() const { return size.size(); }

    /// Turns provisional ids (per beam, -1 = none) into compact labels 0..count-1 following the
    /// union-find roots, and fills size and mean_range. `provisional` is overwritten.
    void finalize(const Scan& scan, std::vector<std::int32_t>& provisional, DisjointSets& sets);

  private:
    std::vector<std::int32_t> compact_;  // scratch: root -> label
    std::vector<double> sums_;           // scratch: range sums
};

/// Sec. 3.2.4: clusters with fewer than m_threshold points are noise.
///
/// With min_object_size_m > 0 (the range-aware variant) the bar depends on range: a cluster
/// at mean range r needs ceil(min_object_size_m / (r * resolution)) points, the number of beams
/// an object of that width returns, clamped to [min_points_floor, m_threshold]. Far small
/// objects (chair legs at 6 m span 2-3 beams) then survive while single-beam outliers do not.
struct ClusterFilterParams {
    std::size_t m_threshold = 10;      // points; Sec. 3.2.4
    double min_object_size_m = 0.0;    // m; 0 = the paper's fixed threshold
    std::size_t min_points_floor = 3;  // points; lower clamp of the range-aware bar
};

/// Marks noise clusters in `c` and clears their beams' valid flags in `scan`.
/// Returns the number of points removed.
std::size_t filterClusters(const ClusterFilterParams& p, Scan& scan, Clusters& c);

/// The point-count bar a cluster at mean range r must reach (see ClusterFilterParams).
std::size_t minClusterPoints(const ClusterFilterParams& p, double mean_range, double resolution);

}  // namespace kfd
