#include "kfd/paper/ring_clustering.h"

#include <algorithm>
#include <cmath>
#include "kfd/pipeline/error.h"

namespace kfd {

void RingClustering::initialize(const Params& p) {
    if (!(p.angle_gap_factor > 0.0) || !std::isfinite(p.angle_gap_factor))
        throw ParameterError("angle_gap_factor", "angle_gap_factor must be > 0");
    if (!(p.merge_distance_m >= 0.0) || !std::isfinite(p.merge_distance_m))
        throw ParameterError("merge_distance_m", "merge_distance_m must be >= 0 (0 = automatic)");
    partition_.initialize(p.rings);
    params_ = p;
    ring_blocks_.resize(p.rings.rings);
    last_in_ring_.resize(p.rings.rings);
}

double RingClustering::angularDistance(std::size_t a, std::size_t b, const ScanGeometry& g) const {
    const double d = static_cast<double>(a > b ? a - b : b - a) * g.resolution();
    return wraps_ ? std::min(d, 2.0 * kPi - d) : d;
}

bool RingClustering::tryMerge(const Scan& scan, const Block& a, const Block& b,
                              double d_threshold) {
    // Closest-angle endpoints of the two blocks.
    const std::uint32_t ea[2] = {a.end0, a.end1};
    const std::uint32_t eb[2] = {b.end0, b.end1};
    double best = 1e300;
    std::uint32_t ia = a.end0, ib = b.end0;
    for (const auto i : ea)
        for (const auto j : eb) {
            const double d = angularDistance(i, j, scan.geometry);
            if (d < best) {
                best = d;
                ia = i;
                ib = j;
            }
        }
    if (best > theta_ + 1e-12) return false;  // Formula 9
    const double ra = scan.range[ia], rb = scan.range[ib];
    const double d2 = ra * ra + rb * rb - 2.0 * ra * rb * std::cos(best);  // Formula 10
    if (std::sqrt(std::max(0.0, d2)) > d_threshold) return false;
    return sets_.unite(a.id, b.id);
}

RingClustering::Result RingClustering::cluster(const Scan& scan, Clusters& out) {
    Result res;
    const std::size_t n = scan.range.size();
    const ScanGeometry& g = scan.geometry;
    theta_ = params_.angle_gap_factor * g.resolution();
    wraps_ = n > 1 && g.seamGap() <= theta_ + 1e-12;
    res.theta_threshold = theta_;
    res.r_max = partition_.compute(scan, ring_);        // Sec. 3.2.1, Formulas 6-8
    res.blocks = blocksInRings(scan);                   // Sec. 3.2.2
    if (wraps_) res.merges += joinAcrossSeam(g);        // 360-degree scanners
    res.merges += mergeAdjacentRings(scan, res.r_max);  // Sec. 3.2.3, Formulas 9-10
    out.finalize(scan, provisional_, sets_);
    return res;
}

// Sec. 3.2.2: angle-gap blocks inside each ring (scan order is angle order). Returns how many.
std::size_t RingClustering::blocksInRings(const Scan& scan) {
    const std::size_t n = scan.range.size();
    const ScanGeometry& g = scan.geometry;
    sets_.clear();
    provisional_.assign(n, -1);
    for (auto& v : ring_blocks_) v.clear();
    std::fill(last_in_ring_.begin(), last_in_ring_.end(), -1);
    for (std::size_t i = 0; i < n; ++i) {
        if (!scan.valid[i]) continue;
        const std::size_t k = ring_[i];
        const std::int64_t j = last_in_ring_[k];
        auto& blocks = ring_blocks_[k];
        // Within one pass the gap is measured forward (no wrap); the seam is handled apart.
        if (j >= 0 && static_cast<double>(i - static_cast<std::size_t>(j)) * g.resolution() <=
                          theta_ + 1e-12) {
            blocks.back().last = blocks.back().end1 = static_cast<std::uint32_t>(i);
        } else {
            blocks.push_back(Block{sets_.add(), static_cast<std::uint32_t>(i),
                                   static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i),
                                   static_cast<std::uint32_t>(i)});
        }
        provisional_[i] = static_cast<std::int32_t>(blocks.back().id);
        last_in_ring_[k] = static_cast<std::int64_t>(i);
    }
    std::size_t blocks = 0;
    for (const auto& v : ring_blocks_) blocks += v.size();
    return blocks;
}

// 360-degree scanners: the last and first block of a ring may meet across the seam. Returns
// the unions made.
std::size_t RingClustering::joinAcrossSeam(const ScanGeometry& g) {
    std::size_t merges = 0;
    for (auto& v : ring_blocks_) {
        if (v.size() < 2) continue;
        if (angularDistance(v.back().last, v.front().first, g) <= theta_ + 1e-12) {
            merges += sets_.unite(v.back().id, v.front().id) ? 1 : 0;
            // One block now: its endpoints are the outer ends of the two halves.
            v.front().end0 = v.back().first;
            v.back().end1 = v.front().last;
            v.back().end0 = v.back().first;
            v.front().end1 = v.front().last;
        }
    }
    return merges;
}

// Sec. 3.2.3: merge blocks of adjacent rings (Formulas 9-10). Returns the unions made.
std::size_t RingClustering::mergeAdjacentRings(const Scan& scan, double r_max) {
    const ScanGeometry& g = scan.geometry;
    const std::size_t t = params_.rings.rings;
    std::size_t merges = 0;
    // + 1e-6: theta / resolution is an integer in exact arithmetic (factor x resolution) but can
    // round to just below it, which would skip pairs exactly theta apart.
    const double gap_beams = g.resolution() > 0 ? theta_ / g.resolution() + 1e-6 : 0.0;
    for (std::size_t k = 0; k + 1 < t; ++k) {
        const auto& inner = ring_blocks_[k];
        const auto& outer = ring_blocks_[k + 1];
        if (inner.empty() || outer.empty()) continue;
        const double r_k = partition_.outerRadius(k + 1, r_max);
        const double d_thr = params_.merge_distance_m > 0.0 ? params_.merge_distance_m
                                                            : 2.0 * r_k * std::sin(0.5 * theta_);
        std::size_t p = 0;
        for (const Block& a : inner) {
            while (p < outer.size() && static_cast<double>(outer[p].last) + gap_beams < a.first)
                ++p;
            for (std::size_t q = p;
                 q < outer.size() && static_cast<double>(outer[q].first) <= a.last + gap_beams; ++q)
                merges += tryMerge(scan, a, outer[q], d_thr) ? 1 : 0;
        }
        if (wraps_) {  // pairs that meet across the seam
            merges += tryMerge(scan, inner.front(), outer.back(), d_thr) ? 1 : 0;
            merges += tryMerge(scan, inner.back(), outer.front(), d_thr) ? 1 : 0;
        }
    }
    return merges;
}

}  // namespace kfd
