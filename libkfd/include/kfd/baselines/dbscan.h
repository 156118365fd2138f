// DBSCAN denoiser (baseline, the paper's comparison in Sec. 4: Eps 0.7 m, minPts 10).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/baselines/neighbour_search.h"
#include "kfd/core/clusters.h"
#include "kfd/core/error.h"
#include "kfd/core/scan.h"

namespace kfd {

/// Ester et al. 1996 on the scan's valid points in Cartesian coordinates. A point with at least
/// min_pts points (itself included) within eps is a core point; clusters are the core points
/// reachable from each other plus their border points; the rest is noise and is removed.
/// Neighbour queries use a k-d tree (NeighbourSearch2D, nanoflann), so a scan costs O(n log n), not
/// O(n^2).
class DbscanFilter {
  public:
    struct Params {
        double eps_m = 0.7;        // Eps (m), the paper's DBSCAN setting
        std::size_t min_pts = 10;  // minPts, the paper's DBSCAN setting
    };
    struct Result {
        std::size_t points_in = 0;
        std::size_t clusters = 0;
        std::size_t points_removed = 0;  // noise points invalidated
    };

    DbscanFilter() = default;
    explicit DbscanFilter(const Params& p) { initialize(p); }
    void initialize(const Params& p);  // kfd::ParameterError on bad values
    const Params& params() const { return params_; }

    /// Clusters the valid points and invalidates the noise points.
    Result filter(Scan& scan);

    /// Per-beam cluster label of the last scan (-1 = invalid or noise).
    const std::vector<std::int32_t>& labels() const { return label_; }

  private:
    Params params_;
    NeighbourSearch2D tree_;
    ScanPoints pts_;  // the valid beams as points
    std::vector<std::int32_t> point_label_;
    std::vector<std::uint32_t> neighbours_, queue_;
    std::vector<std::int32_t> label_;
};

}  // namespace kfd
