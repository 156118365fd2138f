#include "kfd/core/kdtree2d.h"

#include <algorithm>

namespace kfd {

void KdTree2D::build(const float* x, const float* y, std::size_t n) {
    x_ = x;
    y_ = y;
    idx_.resize(n);
    for (std::size_t i = 0; i < n; ++i) idx_[i] = static_cast<std::uint32_t>(i);
    buildRange(0, n, 0);
}

void KdTree2D::buildRange(std::size_t lo, std::size_t hi, int depth) {
    if (hi - lo <= 1) return;
    const std::size_t mid = (lo + hi) / 2;
    const float* c = (depth % 2 == 0) ? x_ : y_;
    std::nth_element(idx_.begin() + lo, idx_.begin() + mid, idx_.begin() + hi,
                     [c](std::uint32_t a, std::uint32_t b) { return c[a] < c[b]; });
    buildRange(lo, mid, depth + 1);
    buildRange(mid + 1, hi, depth + 1);
}

void KdTree2D::radius(float qx, float qy, float r, std::vector<std::uint32_t>& out) const {
    out.clear();
    query(0, idx_.size(), 0, qx, qy, r * r, out);
}

void KdTree2D::query(std::size_t lo, std::size_t hi, int depth, float qx, float qy, float r2,
                     std::vector<std::uint32_t>& out) const {
    if (lo >= hi) return;
    const std::size_t mid = (lo + hi) / 2;
    const std::uint32_t p = idx_[mid];
    const float dx = x_[p] - qx, dy = y_[p] - qy;
    if (dx * dx + dy * dy <= r2) out.push_back(p);
    const float diff = (depth % 2 == 0) ? dx : dy;  // splitting coordinate minus query
    // Left subtree holds coordinates <= the median, right subtree >= it.
    if (diff >= 0 || diff * diff <= r2) query(lo, mid, depth + 1, qx, qy, r2, out);
    if (diff <= 0 || diff * diff <= r2) query(mid + 1, hi, depth + 1, qx, qy, r2, out);
}

}  // namespace kfd
