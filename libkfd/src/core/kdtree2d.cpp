#include "kfd/core/kdtree2d.h"

#include <algorithm>
#include <cmath>

namespace kfd {

void ScanPoints::assign(const Scan& scan) {
    x.clear();
    y.clear();
    beam.clear();
    nonfinite.clear();
    for (std::size_t i = 0; i < scan.range.size(); ++i) {
        if (!scan.valid[i]) continue;
        if (!std::isfinite(scan.range[i])) {
            nonfinite.push_back(static_cast<std::uint32_t>(i));
            continue;
        }
        const double a = scan.geometry.angle(i);
        x.push_back(static_cast<float>(scan.range[i] * std::cos(a)));
        y.push_back(static_cast<float>(scan.range[i] * std::sin(a)));
        beam.push_back(static_cast<std::uint32_t>(i));
    }
}

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

void KdTree2D::knn(float qx, float qy, std::size_t k, std::vector<std::uint32_t>& idx,
                   std::vector<float>& dist2) const {
    idx.clear();
    dist2.clear();
    if (k == 0) return;
    const std::size_t kept = std::min(k, idx_.size());
    idx.reserve(kept);  // no-op once the caller's vectors are large enough
    dist2.reserve(kept);
    nearest(0, idx_.size(), 0, KnnQuery{qx, qy, kept, &idx, &dist2});
}

void KdTree2D::nearest(std::size_t lo, std::size_t hi, int depth, const KnnQuery& q) const {
    if (lo >= hi) return;
    const std::size_t mid = (lo + hi) / 2;
    const std::uint32_t p = idx_[mid];
    const float dx = x_[p] - q.qx, dy = y_[p] - q.qy;
    const float d2 = dx * dx + dy * dy;
    auto& idx = *q.idx;
    auto& dist2 = *q.dist2;
    // Offer p to the candidate list, kept sorted by (distance, index) and at most k long.
    const bool full = idx.size() == q.k;
    if (!full || d2 < dist2.back() || (d2 == dist2.back() && p < idx.back())) {
        if (full) {
            idx.pop_back();
            dist2.pop_back();
        }
        std::size_t pos = idx.size();
        idx.push_back(p);
        dist2.push_back(d2);
        for (; pos > 0 && (dist2[pos - 1] > d2 || (dist2[pos - 1] == d2 && idx[pos - 1] > p));
             --pos) {
            idx[pos] = idx[pos - 1];
            dist2[pos] = dist2[pos - 1];
        }
        idx[pos] = p;
        dist2[pos] = d2;
    }
    const float diff = (depth % 2 == 0) ? dx : dy;  // splitting coordinate minus query
    // Visit the query's side first. Every point of the other side is at least |diff| away along
    // the splitting axis, so its squared distance is >= diff * diff (also in float, as
    // rounding is monotonic): skip that side when even that cannot beat the current k-th
    // candidate. "<=" keeps ties, which may win on index.
    const std::size_t nearLo = diff >= 0 ? lo : mid + 1, nearHi = diff >= 0 ? mid : hi;
    const std::size_t farLo = diff >= 0 ? mid + 1 : lo, farHi = diff >= 0 ? hi : mid;
    nearest(nearLo, nearHi, depth + 1, q);
    if (idx.size() < q.k || diff * diff <= dist2.back()) nearest(farLo, farHi, depth + 1, q);
}

}  // namespace kfd
