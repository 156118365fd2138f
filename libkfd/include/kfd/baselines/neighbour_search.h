// 2D neighbour search for the DBSCAN, radius-outlier and statistical-outlier baselines: a thin
// wrapper over nanoflann's k-d tree (kept out of this header). std only in the interface.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "kfd/pipeline/scan.h"

namespace kfd {

/// The Cartesian points of a scan's valid beams, for the neighbour-based denoisers (DBSCAN,
/// radius and statistical outlier removal). Buffers are reused between scans.
struct ScanPoints {
    std::vector<float> x, y;          // m, sensor frame
    std::vector<std::uint32_t> beam;  // point -> beam index
    /// Valid beams without a usable range (no position): NaN, +-inf, negative or above
    /// kMaxScanRangeM (kfd::isUsableRange); the baselines treat them as noise.
    std::vector<std::uint32_t> nonfinite;
    /// Rebuilds the points from the scan's valid beams with a usable range.
    void assign(const Scan& scan);
    std::size_t size() const { return x.size(); }
};

/// A static 2D k-d tree (nanoflann's KDTreeSingleIndexAdaptor, L2 in float) built over a point
/// set once per scan. The index object and the caller's output vectors are reused across builds,
/// so steady state needs no operator new (nanoflann's node pool takes its blocks from malloc at
/// each build). Points are stored by index into the caller's x/y arrays.
///
/// Distances are float dx*dx + dy*dy, as the brute-force references compute them. Differences
/// from nanoflann's own result sets, made so the answers are unique and match the references:
/// radius() is inclusive (nanoflann's RadiusResultSet keeps d2 < r2 only), and knn() breaks
/// equal distances by increasing index everywhere, also at the k-th place (nanoflann's
/// KNNResultSet keeps whichever tied point it visits first).
class NeighbourSearch2D {
  public:
    NeighbourSearch2D();
    ~NeighbourSearch2D();
    NeighbourSearch2D(const NeighbourSearch2D&) = delete;
    NeighbourSearch2D& operator=(const NeighbourSearch2D&) = delete;

    /// Builds the tree over n points. The arrays must outlive the queries.
    void build(const float* x, const float* y, std::size_t n);

    /// Writes to `out` (cleared first) the indices of the points within `radius` (inclusive)
    /// of (qx, qy), in no particular order, stopping as soon as `max_count` were found (then
    /// which ones is unspecified; fewer than max_count means all of them). O(log n + k) on
    /// average, k = min(neighbours, max_count): callers that only need "at least m" pass m, so
    /// a dense neighbourhood costs O(m), not O(n), and `out` never holds more than max_count.
    void radius(float qx, float qy, float radius, std::vector<std::uint32_t>& out,
                std::size_t max_count = static_cast<std::size_t>(-1)) const;

    /// Writes to `idx` and `dist2` (both cleared first) the min(k, n) points nearest to
    /// (qx, qy) and their squared distances (float, dx*dx + dy*dy as in radius()), by increasing
    /// distance; equal distances by increasing index, so the answer is unique. Nothing is
    /// excluded: a query at a data point returns that point (distance 0) among the others, and
    /// callers that want neighbours only skip it. Allocates only while the vectors grow.
    void knn(float qx, float qy, std::size_t k, std::vector<std::uint32_t>& idx,
             std::vector<float>& dist2) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace kfd
