// Distance filter: the paper's Algorithm 1 (Sec. 3.1.1, "Preprocessing").
#pragma once

#include <cstddef>

#include "kfd/core/error.h"
#include "kfd/core/scan.h"

namespace kfd {

/// Algorithm 1: a range is usable only when min_range <= r <= max_range. Non-finite ranges and
/// beams already flagged invalid (e.g. by the driver or MRPT) are never usable.
class DistanceFilter {
  public:
    struct Params {
        double min_range = 0.1;   // m; the paper's MIT sensor minimum
        double max_range = 30.0;  // m; the paper's MIT sensor maximum
    };

    struct Result {
        std::size_t valid_in = 0;  // beams flagged valid on input
        std::size_t removed_non_finite = 0;
        std::size_t removed_out_of_range = 0;
        std::size_t valid_out = 0;  // beams still valid afterwards
    };

    DistanceFilter() = default;
    explicit DistanceFilter(const Params& p) { initialize(p); }

    /// Throws kfd::ParameterError on inconsistent parameters.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    /// Clears the valid flag of every beam Algorithm 1 drops. O(beams), no allocation.
    Result filter(Scan& scan) const;

  private:
    Params params_;
    // The range limits as floats that compare with a float range exactly as the doubles do:
    // r >= min_range <=> r >= lo_, r <= max_range <=> r <= hi_ (the loop runs in float).
    float lo_ = 0.1f, hi_ = 30.0f;
};

}  // namespace kfd
