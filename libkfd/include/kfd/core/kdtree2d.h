// A static 2D k-d tree for radius queries (used by the DBSCAN baseline). std only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace kfd {

/// Built over a point set once per scan; buffers are reused across builds (no allocation in
/// steady state). Points are stored by index into the caller's x/y arrays.
class KdTree2D {
  public:
    /// Builds the tree over n points. The arrays must outlive the queries.
    void build(const float* x, const float* y, std::size_t n);

    /// Appends to `out` (cleared first) the indices of all points within `radius` (inclusive)
    /// of (qx, qy). O(log n + k) on average.
    void radius(float qx, float qy, float radius, std::vector<std::uint32_t>& out) const;

  private:
    void buildRange(std::size_t lo, std::size_t hi, int depth);
    void query(std::size_t lo, std::size_t hi, int depth, float qx, float qy, float r2,
               std::vector<std::uint32_t>& out) const;

    const float* x_ = nullptr;
    const float* y_ = nullptr;
    std::vector<std::uint32_t> idx_;  // implicit tree: median of [lo, hi) at (lo + hi) / 2
};

}  // namespace kfd
