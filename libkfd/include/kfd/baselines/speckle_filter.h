// Speckle filter (baseline): ROS laser_filters' LaserScanSpeckleFilter, written from its published
// definition (speckle_filter.h, noetic-devel) on a kfd scan. std only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Every run of `window` consecutive beams starting at beam i (i = 0 .. n - window) is tested;
/// each beam of a run that passes is kept, and so is every beam whose range is above
/// max_range (it is not tested); every other valid beam is removed.
///  - distance (radius = false): the run passes when all its beams are valid and each
///    differs from the first by at most max_range_difference (m);
///  - radius (radius = true): the beams j within `window` of i (either side, in order from
///    i - window) are counted while |p_i p_j| <= max_range_difference, until `window` of them
///    are; the run passes when that many are found (its first beam need not be valid to
///    be counted against, as in laser_filters, but an invalid first beam never passes).
/// A scan of at most window + 1 beams is left as it is (laser_filters' guard).
/// Defaults: the configuration of issue 39's table, distance, 80 m, 0.3 m, window 2.
/// Time O(n window); memory O(n).
class SpeckleFilter {
  public:
    struct Params {
        bool radius = false;                // false: distance test; true: radius outlier test
        double max_range = 80.0;            // m: beams farther than this are never removed
        double max_range_difference = 0.3;  // m: range difference (distance) or distance (radius)
        std::size_t window = 2;             // beams per run (distance) / neighbours (radius)
    };
    struct Result {
        std::size_t points_in = 0;       // valid beams on input
        std::size_t points_removed = 0;  // beams invalidated
    };

    SpeckleFilter() = default;
    explicit SpeckleFilter(const Params& p) { initialize(p); }
    /// kfd::ParameterError unless max_range >= 0, max_range_difference >= 0, window in [1, 100].
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    Result filter(Scan& scan);

  private:
    bool distanceRunPasses(const Scan& scan, std::size_t i) const;
    bool radiusRunPasses(const Scan& scan, std::size_t i) const;

    Params params_;
    std::vector<std::uint8_t> keep_;
};

}  // namespace kfd
