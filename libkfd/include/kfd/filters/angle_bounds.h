// Angular bounds (laser_filters' LaserScanAngularBoundsFilter and ...InPlace) as the stage
// "angle_bounds": beams outside an angle interval removed (or inside it). std only.
#pragma once

#include <cstddef>
#include <vector>

#include "kfd/filters/removal_stage.h"
#include "kfd/pipeline/scan.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Beam i's direction a_i (ScanGeometry::angle: sensor frame, 0 = forward, counter-clockwise
/// positive, in (-180, 180] degrees after wrapping) is tested against [lower_deg, upper_deg]:
/// a valid beam outside it is removed, or, with remove_inside, a valid beam inside it (a
/// mount that blocks part of the view). The beams stay (kfd never deletes beams), so the
/// output keeps the driver's beam count, as laser_filters' InPlace variant does.
/// Time O(n); no allocation.
class AngleBounds {
  public:
    struct Params {
        double lower_deg = -180.0;   // deg, lowest kept direction
        double upper_deg = 180.0;    // deg, highest kept direction
        bool remove_inside = false;  // remove the beams inside [lower, upper] instead
    };
    struct Result {
        std::size_t points_in = 0;       // valid beams on input
        std::size_t points_removed = 0;  // valid beams removed
    };

    AngleBounds() = default;
    explicit AngleBounds(const Params& p) { initialize(p); }
    /// kfd::ParameterError unless -180 <= lower_deg <= upper_deg <= 180.
    void initialize(const Params& p);
    const Params& params() const { return params_; }
    Result filter(Scan& scan) const;

  private:
    Params params_;
};

class AngleBoundsStage : public RemovalStage<AngleBounds> {
  public:
    static constexpr const char* kName = "angle_bounds";
    static constexpr const char* kHelp =
        "removes beams outside [lower, upper] degrees (or inside; laser_filters' angular bounds)";
    /// Keys: angle_lower_deg, angle_upper_deg, angle_remove_inside.
    static std::vector<StageKey> keys();
    static std::vector<StageColumn> columns();
    static std::vector<StageCounter> counters();
    explicit AngleBoundsStage(const Params& p = {}) : RemovalStage(p) {}
    const char* name() const override { return kName; }
};

}  // namespace kfd
