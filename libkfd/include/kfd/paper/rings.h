// Region segmentation into equal-area rings: Sec. 3.2.1, Formulas 6-8.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Splits the disc of radius r_max around the sensor into t rings of equal area: ring i
/// (1-based) spans (r_{i-1}, r_i] with r_i = sqrt(i) * r_max / sqrt(t) (Formulas 6-8), so
/// pi*r_i^2 - pi*r_{i-1}^2 = pi*r_max^2 / t for every ring.
class RingPartition {
  public:
    struct Params {
        std::size_t rings = 5;  // t (the paper's value)
        double r_max = 0.0;     // m; 0 = the farthest valid point of each scan (the paper's choice)
    };

    RingPartition() = default;
    explicit RingPartition(const Params& p) { initialize(p); }
    /// Throws kfd::ParameterError when rings == 0, rings > 254 (255 marks
    /// invalid beams) or r_max < 0.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    /// Assigns each valid beam its 0-based ring (255 for invalid beams) and returns the r_max
    /// used (0 when the scan has no valid beam). O(beams).
    double compute(const Scan& scan, std::vector<std::uint8_t>& ring_of_beam) const;

    /// Outer radius r_i of 1-based ring i for a given r_max (Formula 8).
    double outerRadius(std::size_t i, double r_max) const;
    /// 0-based ring of a range r (Formula 8 inverted: i = ceil(t * r^2 / r_max^2)).
    std::size_t ringOf(double r, double r_max) const;

    static constexpr std::uint8_t kNoRing = 255;

  private:
    Params params_;
};

}  // namespace kfd
