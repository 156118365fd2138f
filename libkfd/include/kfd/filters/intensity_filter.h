// An intensity threshold (laser_filters' LaserScanIntensityFilter) as the stage "intensity":
// returns whose intensity is outside [lower, upper] removed. std only.
#pragma once

#include <cstddef>
#include <vector>

#include "kfd/filters/removal_stage.h"
#include "kfd/pipeline/scan.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// A valid beam whose intensity (Scan::intensity, the driver's units) is below lower or above
/// upper is removed (a weak return off glass or a dark surface, a retro-reflector's glare).
/// A scan without one intensity per beam is left as it is and counted (no_intensity).
/// Time O(n); no allocation.
class IntensityFilter {
  public:
    struct Params {
        double lower = 0.0;  // driver's intensity units: weaker returns are removed
        double upper = 1e9;  // driver's intensity units: stronger returns are removed
    };
    struct Result {
        std::size_t points_in = 0;       // valid beams on input
        std::size_t points_removed = 0;  // valid beams removed
        std::size_t no_intensity = 0;    // 1 when the scan has no intensities
    };

    IntensityFilter() = default;
    explicit IntensityFilter(const Params& p) { initialize(p); }
    /// kfd::ParameterError unless lower <= upper.
    void initialize(const Params& p);
    const Params& params() const { return params_; }
    Result filter(Scan& scan) const;

  private:
    Params params_;
};

class IntensityStage : public RemovalStage<IntensityFilter> {
  public:
    static constexpr const char* kName = "intensity";
    static constexpr const char* kHelp =
        "removes returns whose intensity is outside [lower, upper] (laser_filters' intensity "
        "filter)";
    /// Keys: intensity_lower, intensity_upper.
    static std::vector<StageKey> keys();
    static std::vector<StageColumn> columns();
    static std::vector<StageCounter> counters();
    explicit IntensityStage(const Params& p = {}) : RemovalStage(p) {}
    const char* name() const override { return kName; }
};

}  // namespace kfd
