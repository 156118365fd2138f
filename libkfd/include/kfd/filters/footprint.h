// The robot's own body (laser_filters' LaserScanBoxFilter and LaserScanPolygonFilter) as the
// stage "footprint": returns inside a box or a polygon in the robot's frame removed. std only.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "kfd/filters/removal_stage.h"
#include "kfd/pipeline/scan.h"
#include "kfd/pipeline/stage_outputs.h"

namespace kfd {

/// Each valid return is placed in the robot's frame (the scan's sensor_pose, i.e. MRPT's
/// sensorPose or the bag's tf from base to laser, then r (cos a, sin a)); it is removed when
/// it lies inside the box [min_x, max_x] x [min_y, max_y] (a box with min < max on both axes;
/// the default, all 0, is none) or inside the polygon (3 or more vertices, even-odd rule; none
/// by default). Both may be given: a return inside either is removed.
/// Time O(n * vertices); no allocation.
class Footprint {
  public:
    struct Vertex {
        double x = 0.0, y = 0.0;  // m, robot frame
    };
    struct Params {
        double min_x = 0.0, max_x = 0.0;  // m, robot frame (x forward)
        double min_y = 0.0, max_y = 0.0;  // m, robot frame (y left)
        std::vector<Vertex> polygon;      // m, robot frame; empty = none
    };
    struct Result {
        std::size_t points_in = 0;       // valid beams on input
        std::size_t points_removed = 0;  // valid beams removed (inside the box or polygon)
    };

    Footprint() = default;
    explicit Footprint(const Params& p) { initialize(p); }
    /// kfd::ParameterError when min > max on an axis, a coordinate is not finite, or the
    /// polygon has 1 or 2 vertices.
    void initialize(const Params& p);
    const Params& params() const { return params_; }
    Result filter(Scan& scan) const;
    /// Whether (x, y) in the robot's frame is inside the box or the polygon.
    bool inside(double x, double y) const;

    /// "[[x, y], [x, y], ...]" (laser_filters' footprint form; ';' between vertices and
    /// brackets are optional) -> vertices; kfd::ParameterError(field) on anything else.
    static std::vector<Vertex> parsePolygon(const std::string& field, const std::string& text);
    static std::string formatPolygon(const std::vector<Vertex>& polygon);

  private:
    Params params_;
    bool box_ = false;
};

class FootprintStage : public RemovalStage<Footprint> {
  public:
    static constexpr const char* kName = "footprint";
    static constexpr const char* kHelp =
        "removes returns on the robot's own body: a box and/or a polygon in the robot's frame "
        "(laser_filters' box and polygon filters)";
    /// Keys: footprint_min_x, footprint_max_x, footprint_min_y, footprint_max_y,
    /// footprint_polygon.
    static std::vector<StageKey> keys();
    static std::vector<StageColumn> columns();
    static std::vector<StageCounter> counters();
    explicit FootprintStage(const Params& p = {}) : RemovalStage(p) {}
    const char* name() const override { return kName; }
};

}  // namespace kfd
