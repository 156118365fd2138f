#include "kfd/baselines/neighbour_search.h"

#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace kfd {

void ScanPoints::assign(const Scan& scan) {
    x.clear();
    y.clear();
    beam.clear();
    nonfinite.clear();
    for (std::size_t i = 0; i < scan.range.size(); ++i) {
        if (!scan.valid[i]) continue;
        if (!isUsableRange(scan.range[i])) {
            nonfinite.push_back(static_cast<std::uint32_t>(i));
            continue;
        }
        const double a = scan.geometry.angle(i);
        x.push_back(static_cast<float>(scan.range[i] * std::cos(a)));
        y.push_back(static_cast<float>(scan.range[i] * std::sin(a)));
        beam.push_back(static_cast<std::uint32_t>(i));
    }
}

namespace {

// nanoflann's dataset adaptor over the caller's x/y arrays.
struct Cloud {
    const float* x = nullptr;
    const float* y = nullptr;
    std::size_t n = 0;
    std::size_t kdtree_get_point_count() const { return n; }
    float kdtree_get_pt(std::uint32_t i, std::size_t dim) const { return dim == 0 ? x[i] : y[i]; }
    template <class BBox>
    bool kdtree_get_bbox(BBox&) const {
        return false;
    }
};

using Metric = nanoflann::L2_Simple_Adaptor<float, Cloud, float, std::uint32_t>;
using Tree = nanoflann::KDTreeSingleIndexAdaptor<Metric, Cloud, 2, std::uint32_t>;

// nanoflann offers a leaf point only when d2 < worstDist(), and prunes a subtree when its lower
// bound (summed incrementally in float, so a few ulps above the exact distance at worst) exceeds
// worstDist(). Reporting a bound slightly above the real one keeps every point at exactly the
// bound (ties) in play; addPoint() then decides with the exact comparison.
float slack(float bound) {
    return std::nextafter(bound * (1.0f + 1e-5f), std::numeric_limits<float>::max());
}

// Every index within r2 (inclusive), straight into the caller's vector, up to `max` of them:
// returning false from addPoint() ends nanoflann's search (1.4: searchLevel returns at once).
struct RadiusSet {
    float r2;
    float worst;
    std::vector<std::uint32_t>* out;
    std::size_t max;
    bool full() const { return true; }
    float worstDist() const { return worst; }
    bool addPoint(float d2, std::uint32_t i) {
        if (d2 <= r2) out->push_back(i);
        return out->size() < max;
    }
};

// The k nearest by (distance, index), kept sorted in the caller's vectors.
struct KnnSet {
    std::size_t k;
    std::vector<std::uint32_t>* idx;
    std::vector<float>* dist2;
    bool full() const { return idx->size() == k; }
    float worstDist() const {
        return full() ? slack(dist2->back()) : std::numeric_limits<float>::max();
    }
    bool addPoint(float d2, std::uint32_t p) {
        auto& I = *idx;
        auto& D = *dist2;
        if (full() && (d2 > D.back() || (d2 == D.back() && p > I.back()))) return true;
        if (full()) {
            I.pop_back();
            D.pop_back();
        }
        std::size_t pos = I.size();
        I.push_back(p);
        D.push_back(d2);
        for (; pos > 0 && (D[pos - 1] > d2 || (D[pos - 1] == d2 && I[pos - 1] > p)); --pos) {
            I[pos] = I[pos - 1];
            D[pos] = D[pos - 1];
        }
        I[pos] = p;
        D[pos] = d2;
        return true;
    }
};

}  // namespace

struct NeighbourSearch2D::Impl {
    Cloud cloud;
    Tree tree{2, cloud,
              nanoflann::KDTreeSingleIndexAdaptorParams(
                  10, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex)};
};

NeighbourSearch2D::NeighbourSearch2D() : impl_(std::make_unique<Impl>()) {}
NeighbourSearch2D::~NeighbourSearch2D() = default;

void NeighbourSearch2D::build(const float* x, const float* y, std::size_t n) {
    impl_->cloud = Cloud{x, y, n};
    impl_->tree.buildIndex();  // reuses the index vector; the node pool is refilled
}

void NeighbourSearch2D::radius(float qx, float qy, float r, std::vector<std::uint32_t>& out,
                               std::size_t max_count) const {
    out.clear();
    if (impl_->cloud.n == 0 || max_count == 0) return;
    const float r2 = r * r;
    RadiusSet set{r2, slack(r2), &out, max_count};
    const float q[2] = {qx, qy};
    impl_->tree.findNeighbors(set, q, nanoflann::SearchParams());
}

void NeighbourSearch2D::knn(float qx, float qy, std::size_t k, std::vector<std::uint32_t>& idx,
                            std::vector<float>& dist2) const {
    idx.clear();
    dist2.clear();
    if (k == 0 || impl_->cloud.n == 0) return;
    const std::size_t kept = std::min(k, impl_->cloud.n);
    idx.reserve(kept);  // no-op once the caller's vectors are large enough
    dist2.reserve(kept);
    KnnSet set{kept, &idx, &dist2};
    const float q[2] = {qx, qy};
    impl_->tree.findNeighbors(set, q, nanoflann::SearchParams());
}

}  // namespace kfd
