#include "kfd/sim/world.h"

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "kfd/io/rawlog_source.h"

namespace kfd {
namespace {

using mrpt::maps::COccupancyGridMap2D;
constexpr float kOccupied = 0.0f;  // MRPT cells hold the probability of being free

void segment(COccupancyGridMap2D& g, double x0, double y0, double x1, double y1,
             double thickness = 0.1) {
    const double len = std::hypot(x1 - x0, y1 - y0);
    const double step = 0.5 * g.getResolution();
    const int n = static_cast<int>(std::ceil(len / step)) + 1;
    const int w = static_cast<int>(std::ceil(0.5 * thickness / g.getResolution()));
    for (int k = 0; k <= n; ++k) {
        const double t = static_cast<double>(k) / n;
        const int cx = g.x2idx(x0 + t * (x1 - x0)), cy = g.y2idx(y0 + t * (y1 - y0));
        for (int dx = -w; dx <= w; ++dx)
            for (int dy = -w; dy <= w; ++dy) g.setCell(cx + dx, cy + dy, kOccupied);
    }
}

void box(COccupancyGridMap2D& g, double x0, double y0, double x1, double y1) {
    for (double x = x0; x <= x1; x += 0.5 * g.getResolution())
        for (double y = y0; y <= y1; y += 0.5 * g.getResolution())
            g.setCell(g.x2idx(x), g.y2idx(y), kOccupied);
}

void disc(COccupancyGridMap2D& g, double cx, double cy, double r) {
    const double res = g.getResolution();
    for (double x = cx - r; x <= cx + r; x += 0.5 * res)
        for (double y = cy - r; y <= cy + r; y += 0.5 * res)
            if (std::hypot(x - cx, y - cy) <= r) g.setCell(g.x2idx(x), g.y2idx(y), kOccupied);
}

World office() {
    World w;
    w.name = "office";
    w.grid.setSize(-1, 25, -1, 15, 0.05f, 1.0f);
    auto& g = w.grid;
    // Outer walls.
    segment(g, 0, 0, 24, 0);
    segment(g, 24, 0, 24, 14);
    segment(g, 24, 14, 0, 14);
    segment(g, 0, 14, 0, 0);
    // Interior walls with doorways.
    segment(g, 8, 0, 8, 6);
    segment(g, 8, 7.5, 8, 14);
    segment(g, 16, 0, 16, 3);
    segment(g, 16, 4.5, 16, 10);
    segment(g, 16, 11.5, 16, 14);
    segment(g, 16, 7, 19, 7);
    segment(g, 20.5, 7, 24, 7);
    // Pillars, desks and chair legs (small real objects the denoiser must keep).
    disc(g, 4, 5.2, 0.25);
    disc(g, 4, 10, 0.25);
    disc(g, 12, 7.2, 0.25);
    box(g, 1, 12, 3, 13);
    box(g, 10, 1, 13, 2);
    box(g, 20, 12, 23, 13);
    for (const auto& c : {std::pair{5.5, 1.5}, {13.5, 12.0}, {22.0, 2.0}})
        for (const auto& d : {std::pair{-0.2, -0.2}, {0.2, -0.2}, {-0.2, 0.2}, {0.2, 0.2}})
            disc(g, c.first + d.first, c.second + d.second, 0.025);
    w.route = {{2, 3.5},    {6, 3.5},      {6, 6.75, 3, 180}, {10, 6.75},
               {12, 9.5},   {14, 10.75},   {19, 10.75, 5, 0}, {19.75, 9},
               {19.75, 5},  {19.75, 3.75}, {14, 3.75},        {10, 4.5},
               {9.5, 6.75}, {6, 6.75},     {2, 6.75},         {2, 3.5, 2, 360}};
    return w;
}

World corridor() {
    World w;
    w.name = "corridor";
    w.grid.setSize(-1, 61, -1, 3.4, 0.05f, 1.0f);
    auto& g = w.grid;
    segment(g, 0, 0, 60, 0);
    segment(g, 0, 2.4, 60, 2.4);
    segment(g, 0, 0, 0, 2.4);
    segment(g, 60, 0, 60, 2.4);
    w.route = {{1, 1.2}, {59, 1.2, 2, 0}, {1, 1.2}};
    return w;
}

}  // namespace

std::vector<std::string> worldNames() { return {"office", "corridor"}; }

World makeWorld(const std::string& name) {
    if (name == "office") return office();
    if (name == "corridor") return corridor();
    throw SimulationError("unknown world '" + name + "' (built-in: office, corridor)");
}

World loadWorld(const std::string& gridmap, const std::string& route_file) {
    World w;
    w.name = gridmap;
    if (!std::ifstream(gridmap)) throw SimulationError("cannot open gridmap " + gridmap);
    checkGzipIntegrity(gridmap);  // MRPT's reader passes a gzip file with a bad trailer
    mrpt::io::CFileGZInputStream in;
    if (!in.open(gridmap)) throw SimulationError("cannot open gridmap " + gridmap);
    try {
        mrpt::serialization::archiveFrom(in) >> w.grid;
    } catch (const std::exception& e) {
        throw SimulationError("cannot read gridmap " + gridmap);
    }
    std::ifstream f(route_file);
    if (!f) throw SimulationError("cannot open route file " + route_file);
    std::string line;
    std::size_t lineno = 0;
    while (std::getline(f, line)) {
        ++lineno;
        const auto b = line.find_first_not_of(" \t\r");
        if (b == std::string::npos || line[b] == '#') continue;
        std::istringstream ss(line);
        Waypoint p;
        if (!(ss >> p.x >> p.y))
            throw SimulationError(route_file + ":" + std::to_string(lineno) +
                                  ": expected 'x y [stop_s [spin_deg]]'");
        ss >> p.stop_s >> p.spin_deg;
        w.route.push_back(p);
    }
    if (w.route.size() < 2) throw SimulationError("a route needs at least two waypoints");
    return w;
}

}  // namespace kfd
