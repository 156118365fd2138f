// A static 2D k-d tree for radius and k-nearest queries (used by the DBSCAN, radius-outlier and
// statistical-outlier baselines). std only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/core/scan.h"

namespace kfd {

/// The Cartesian points of a scan's valid beams, for the neighbour-based denoisers (DBSCAN,
/// radius and statistical outlier removal). Buffers are reused between scans.
struct ScanPoints {
    std::vector<float> x, y;               // m, sensor frame
    std::vector<std::uint32_t> beam;       // point -> beam index
    std::vector<std::uint32_t> nonfinite;  // valid beams without a finite range (no position)
    /// Rebuilds the points from the scan's valid beams with a finite range.
    void assign(const Scan& scan);
    std::size_t size() const { return x.size(); }
};

/// Built over a point set once per scan; buffers are reused across builds (no allocation in
/// steady state). Points are stored by index into the caller's x/y arrays.
class KdTree2D {
  public:
    /// Builds the tree over n points. The arrays must outlive the queries.
    void build(const float* x, const float* y, std::size_t n);

    /// Appends to `out` (cleared first) the indices of all points within `radius` (inclusive)
    /// of (qx, qy). O(log n + k) on average.
    void radius(float qx, float qy, float radius, std::vector<std::uint32_t>& out) const;

    /// Writes to `idx` and `dist2` (both cleared first) the min(k, n) points nearest to
    /// (qx, qy) and their squared distances (float, dx*dx + dy*dy as in radius()), by increasing
    /// distance; equal distances by increasing index, so the answer is unique. Nothing is
    /// excluded: a query at a data point returns that point (distance 0) among the others, and
    /// callers that want neighbours only skip it. Allocates only while the vectors grow.
    void knn(float qx, float qy, std::size_t k, std::vector<std::uint32_t>& idx,
             std::vector<float>& dist2) const;

  private:
    void buildRange(std::size_t lo, std::size_t hi, int depth);
    void query(std::size_t lo, std::size_t hi, int depth, float qx, float qy, float r2,
               std::vector<std::uint32_t>& out) const;
    struct KnnQuery {
        float qx, qy;
        std::size_t k;
        std::vector<std::uint32_t>* idx;
        std::vector<float>* dist2;
    };
    void nearest(std::size_t lo, std::size_t hi, int depth, const KnnQuery& q) const;

    const float* x_ = nullptr;
    const float* y_ = nullptr;
    std::vector<std::uint32_t> idx_;  // implicit tree: median of [lo, hi) at (lo + hi) / 2
};

}  // namespace kfd
