// Shadow (veiling point) filter (baseline): the test of ROS laser_filters' ScanShadowsFilter on
// a kfd scan. std only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// For each valid beam i and each valid beam j within `window` beams of it, the angle at p_i
/// between the ray to p_i and the segment p_i p_j,
///   angle = |atan2(r_j sin(k res), r_i - r_j cos(k res))|, k = j - i,
/// is computed. When it is below min_angle_deg or above max_angle_deg (the segment runs nearly
/// along the ray: a veiling point between two surfaces, or a surface seen at grazing
/// incidence), every valid beam within `neighbors` of i that is farther than r_i is removed.
/// With remove_start (laser_filters' remove_shadow_start_point, noetic) beam i goes too. As in
/// laser_filters, every test reads the input scan. Defaults are laser_filters' example
/// configuration (10 and 170 degrees, window 1, 20 neighbours, the start point kept).
/// Time O(n (window + neighbors)); memory O(n).
class ShadowFilter {
  public:
    struct Params {
        double min_angle_deg = 10.0;   // deg
        double max_angle_deg = 170.0;  // deg
        std::size_t window = 1;        // beams each side tested against
        std::size_t neighbors = 20;    // beams each side removed when farther
        bool remove_start = false;     // also remove the beam whose test failed
    };
    struct Result {
        std::size_t points_in = 0;       // valid beams on input
        std::size_t points_removed = 0;  // beams invalidated
        std::size_t shadow_tests = 0;    // pairs that failed the angle test
    };

    ShadowFilter() = default;
    explicit ShadowFilter(const Params& p) { initialize(p); }
    /// kfd::ParameterError unless 0 <= min < max <= 180, window in [1, 64], neighbors <= 1000.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    Result filter(Scan& scan);

  private:
    Params params_;
    std::vector<std::uint8_t> remove_;
};

}  // namespace kfd
