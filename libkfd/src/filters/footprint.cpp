#include "kfd/filters/footprint.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/stage_keys.h"

namespace kfd {

void Footprint::initialize(const Params& p) {
    for (double v : {p.min_x, p.max_x, p.min_y, p.max_y})
        if (!std::isfinite(v))
            throw ParameterError("min_x", "footprint: box bounds must be finite");
    if (p.min_x > p.max_x || p.min_y > p.max_y)
        throw ParameterError("min_x", "footprint: the box needs min_x <= max_x and min_y <= max_y");
    if (p.polygon.size() == 1 || p.polygon.size() == 2)
        throw ParameterError("polygon", "footprint: a polygon needs 3 or more vertices, not " +
                                            std::to_string(p.polygon.size()));
    for (const auto& v : p.polygon)
        if (!std::isfinite(v.x) || !std::isfinite(v.y))
            throw ParameterError("polygon", "footprint: polygon vertices must be finite");
    params_ = p;
    box_ = p.min_x < p.max_x && p.min_y < p.max_y;
}

bool Footprint::inside(double x, double y) const {
    if (box_ && x >= params_.min_x && x <= params_.max_x && y >= params_.min_y &&
        y <= params_.max_y)
        return true;
    const auto& poly = params_.polygon;
    bool in = false;  // even-odd rule: a ray towards +x crosses the edges an odd number of times
    for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const Vertex &a = poly[i], &b = poly[j];
        if ((a.y > y) != (b.y > y) && x < (b.x - a.x) * (y - a.y) / (b.y - a.y) + a.x) in = !in;
    }
    return in;
}

Footprint::Result Footprint::filter(Scan& scan) const {
    Result r;
    const Pose2D& s = scan.sensor_pose;
    const double c = std::cos(s.phi), sn = std::sin(s.phi);
    for (std::size_t i = 0; i < scan.size(); ++i) {
        if (!scan.valid[i]) continue;
        ++r.points_in;
        if (!box_ && params_.polygon.empty()) continue;
        const double a = scan.geometry.angle(i), d = scan.range[i];
        const double lx = d * std::cos(a), ly = d * std::sin(a);
        if (inside(s.x + c * lx - sn * ly, s.y + sn * lx + c * ly)) {
            scan.valid[i] = 0;
            ++r.points_removed;
        }
    }
    return r;
}

std::vector<Footprint::Vertex> Footprint::parsePolygon(const std::string& field,
                                                       const std::string& text) {
    std::vector<double> numbers;
    const char* p = text.c_str();
    while (*p) {
        if (*p == '[' || *p == ']' || *p == ',' || *p == ';' || *p == ' ' || *p == '\t') {
            ++p;
            continue;
        }
        char* end = nullptr;
        const double v = std::strtod(p, &end);
        if (end == p || !std::isfinite(v))
            throw ParameterError(field, field +
                                            " must be vertices [[x, y], [x, y], ...] in "
                                            "metres, not '" +
                                            text + "'");
        numbers.push_back(v);
        p = end;
    }
    if (numbers.size() % 2 != 0)
        throw ParameterError(field, field + ": an odd count of numbers in '" + text + "'");
    std::vector<Vertex> out;
    for (std::size_t i = 0; i + 1 < numbers.size(); i += 2)
        out.push_back({numbers[i], numbers[i + 1]});
    return out;
}

std::string Footprint::formatPolygon(const std::vector<Vertex>& polygon) {
    std::string s = "[";
    for (std::size_t i = 0; i < polygon.size(); ++i)
        s += (i ? ", [" : "[") + keys::formatReal(polygon[i].x) + ", " +
             keys::formatReal(polygon[i].y) + "]";
    return s + "]";
}

std::vector<StageKey> FootprintStage::keys() {
    using P = Params;
    auto bound = [](const char* name, const char* field, const char* help, double P::*m) {
        return keys::real<P>(name, field, help, -100, 100, false,
                             [m](P& p) -> double& { return p.*m; });
    };
    return {
        bound("footprint_min_x", "min_x", "footprint: box, rearmost x (m, robot frame)", &P::min_x),
        bound("footprint_max_x", "max_x", "footprint: box, foremost x (m); 0 = no box", &P::max_x),
        bound("footprint_min_y", "min_y", "footprint: box, rightmost y (m)", &P::min_y),
        bound("footprint_max_y", "max_y", "footprint: box, leftmost y (m)", &P::max_y),
        keys::custom<P>(
            "footprint_polygon", "polygon",
            "footprint: polygon [[x, y], ...] in the robot's frame (m); [] = none",
            "[] or 3+ vertices [[x, y], ...]",
            [](P& p, const std::string& t) { p.polygon = Footprint::parsePolygon("polygon", t); },
            [](const P& p) { return Footprint::formatPolygon(p.polygon); })};
}

std::vector<StageColumn> FootprintStage::columns() {
    using R = Footprint::Result;
    return {diagnosticColumn<R>("removed_footprint", "returns removed on the robot's footprint",
                                "%zu", [](const R& r) { return r.points_removed; })};
}

std::vector<StageCounter> FootprintStage::counters() {
    using R = Footprint::Result;
    return {diagnosticCounter<R>("points_removed_footprint",
                                 "returns on the robot's footprint removed from kept scans", true,
                                 [](const R& r) { return r.points_removed; })};
}

}  // namespace kfd
