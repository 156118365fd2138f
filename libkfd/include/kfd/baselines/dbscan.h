// DBSCAN denoiser (baseline, the paper's comparison in Sec. 4: Eps 0.7 m, minPts 10).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/baselines/neighbour_search.h"
#include "kfd/paper/clusters.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Ester et al. 1996 on the scan's valid points in Cartesian coordinates. A point with at least
/// min_pts points (itself included) within eps is a core point; clusters are the core points
/// reachable from each other plus their border points; the rest is noise and is removed.
/// The result is exactly the sequential algorithm's (cluster numbers by first core point, a
/// border point in the first cluster that reaches it), computed without its neighbour lists:
///  1. core test: a k-d tree query (NeighbourSearch2D, nanoflann) per point stopping at min_pts
///     hits;
///  2. core points are connected through square cells of side < eps / sqrt(2) (one cell is
///     always connected; neighbouring cells, up to 2 away, are joined by the first core pair
///     within eps, union-find skips pairs already joined);
///  3. a non-core point queries its neighbourhood in full (it has fewer than min_pts points).
/// Bounds per scan of n <= kMaxScanBeams (65 536) beams: memory O(n) (points, tree, cells,
/// labels; no list longer than min_pts is ever stored); time O(n (log n + min_pts)) for steps
/// 1 and 3 and, for step 2, O(n) on typical and fully dense scans (every point within eps of
/// every other: one cell or a few joined at their first pair). The worst case of step 2 is
/// O(n^2) pair tests between adjacent cells with no core pair within eps, which needs points
/// packed against opposite cell borders; stats() counts the work of the last scan.
/// eps_m must be >= kMinEpsM (1e-6 m) so that cell indices stay small.
class DbscanFilter {
  public:
    struct Params {
        double eps_m = 0.7;        // Eps (m), the paper's DBSCAN setting
        std::size_t min_pts = 10;  // minPts, the paper's DBSCAN setting
    };
    static constexpr double kMinEpsM = 1e-6;
    /// Work done on the last scan (for the bounded-work tests; not timing).
    struct Stats {
        std::size_t neighbours_visited = 0;  // neighbour indices returned by tree queries
        std::size_t pairs_tested = 0;        // core pairs compared between cells
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
    const Stats& stats() const { return stats_; }

  private:
    Params params_;
    NeighbourSearch2D tree_;
    ScanPoints pts_;  // the valid beams as points
    struct Cell {
        std::int64_t x, y;
    };
    struct Run {
        std::uint32_t begin, end;  // a cell's points: order_[begin, end)
    };
    Stats stats_;
    std::vector<std::uint8_t> core_;
    std::vector<Cell> cell_;
    std::vector<std::uint32_t> order_;
    std::vector<Run> runs_;
    DisjointSets sets_;
    std::vector<std::int32_t> point_label_, root_label_;
    std::vector<std::uint32_t> neighbours_;
    std::vector<std::int32_t> label_;

    // filter()'s steps, in order (dbscan.cpp says what each does).
    void markCorePoints(float eps);
    void binInCells();
    void joinWithinCells();
    const Run* findRun(std::int64_t cx, std::int64_t cy) const;
    void joinAcrossCells(float eps2);
    std::size_t numberClusters(float eps);
};

}  // namespace kfd
