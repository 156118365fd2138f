// Distance filter: the paper's Algorithm 1 (Sec. 3.1.1, "Preprocessing").
#pragma once

#include <cstddef>
#include <limits>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Algorithm 1: a range is usable only when min_range <= r <= max_range, the limits being the
/// scan's own (the sensor's) unless the parameters narrow them. Non-finite ranges and beams
/// already flagged invalid (by the driver, MRPT or kfd's source: a LaserScan's returns outside
/// [range_min, range_max]) are never usable.
class DistanceFilter {
  public:
    struct Params {
        /// m; 0 = the scan's own minimum (the source flags returns below it invalid). The
        /// paper's MIT presets give 0.1.
        double min_range = 0.0;
        /// m; +inf = the scan's own maximum (Scan::max_range). A finite value narrows it: the
        /// limit used is min(max_range, Scan::max_range). The paper's MIT presets give 30.
        double max_range = std::numeric_limits<double>::infinity();
    };

    struct Result {
        std::size_t valid_in = 0;  // beams flagged valid on input
        std::size_t removed_non_finite = 0;
        std::size_t removed_out_of_range = 0;
        std::size_t valid_out = 0;  // beams still valid afterwards
        double max_range_used = std::numeric_limits<double>::infinity();  // m, the upper limit
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
    float lo_ = 0.0f, hi_ = std::numeric_limits<float>::max();
};

}  // namespace kfd
