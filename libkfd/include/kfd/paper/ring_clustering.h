// The paper's clustering (Algorithm 2): ring-wise angle-gap blocks merged across rings.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/paper/clusters.h"
#include "kfd/paper/rings.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Reference variant of Algorithm 2, as published:
///  1. region segmentation into t equal-area rings (Sec. 3.2.1, Formulas 6-8);
///  2. inside each ring, points in angle order; a new block starts where the angle between
///     consecutive points of that ring exceeds theta_threshold (Sec. 3.2.2);
///  3. a block in ring k and a block in ring k+1 merge when their closest-angle endpoints pass
///     the angle test |theta_a - theta_b| <= theta_threshold (Formula 9) and the law-of-cosines
///     distance d = sqrt(r_a^2 + r_b^2 - 2 r_a r_b cos(theta_a - theta_b)) <= d_threshold
///     (Formula 10) (Sec. 3.2.3).
/// On a scanner whose field of view closes the circle (2*pi - aperture <= theta_threshold),
/// blocks that meet across the +-pi seam are one block.
///
/// d_threshold: unless set, the chord that theta_threshold subtends on the boundary between the
/// two rings, 2 * r_k * sin(theta_threshold / 2) — the largest gap two points on that boundary
/// can have while still passing the angle test. (Our reading; the value is configurable.)
///
/// Cost: O(beams) per scan; the cross-ring sweep visits each pair of angularly overlapping
/// blocks once. No allocation once the buffers have grown to the scan size.
class RingClustering {
  public:
    struct Params {
        RingPartition::Params rings;  // t, r_max (Formulas 6-8)
        double angle_gap_factor =
            10.0;  // theta_threshold = factor x angular resolution (Sec. 3.2.2)
        double merge_distance_m = 0.0;  // d_threshold (Formula 10), m; 0 = chord at ring boundary
    };

    struct Result {
        std::size_t blocks = 0;        // blocks before merging (Sec. 3.2.2)
        std::size_t merges = 0;        // successful unions across rings or the seam (Sec. 3.2.3)
        double r_max = 0.0;            // m, outer radius used for the rings
        double theta_threshold = 0.0;  // rad
    };

    RingClustering() { initialize(Params{}); }
    explicit RingClustering(const Params& p) { initialize(p); }
    void initialize(const Params& p);  // kfd::ParameterError on bad values
    const Params& params() const { return params_; }

    /// Clusters the valid beams of `scan` into `out` (labels, sizes, mean ranges).
    Result cluster(const Scan& scan, Clusters& out);

  private:
    struct Block {
        std::uint32_t id;     // union-find id
        std::uint32_t first;  // first beam (scan order)
        std::uint32_t last;   // last beam
        // The block's endpoints for Formulas 9-10: first and last, except for a block joined
        // across the +-pi seam, whose two halves both carry the outer ends of the whole block.
        std::uint32_t end0;
        std::uint32_t end1;
    };
    double angularDistance(std::size_t a, std::size_t b, const ScanGeometry& g) const;
    bool tryMerge(const Scan& scan, const Block& a, const Block& b, double d_threshold);
    // cluster()'s steps: Sec. 3.2.2, the seam of a 360-degree scan, Sec. 3.2.3.
    std::size_t blocksInRings(const Scan& scan);
    std::size_t joinAcrossSeam(const ScanGeometry& g);
    std::size_t mergeAdjacentRings(const Scan& scan, double r_max);

    Params params_;
    RingPartition partition_;
    double theta_ = 0.0;  // theta_threshold of the current scan
    bool wraps_ = false;  // the current scan closes the circle
    DisjointSets sets_;
    std::vector<std::uint8_t> ring_;
    std::vector<std::int32_t> provisional_;
    std::vector<std::vector<Block>> ring_blocks_;
    std::vector<std::int64_t> last_in_ring_;
};

}  // namespace kfd
