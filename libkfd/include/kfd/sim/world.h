// Simulated indoor worlds: an occupancy grid plus a route through it.
#pragma once

#include <mrpt/maps/COccupancyGridMap2D.h>

#include <string>
#include <vector>

#include "kfd/pipeline/error.h"

namespace kfd {

/// Bad simulation options, an unreadable world or route file, or unwritable output.
class SimulationError : public Error {
  public:
    using Error::Error;
};

/// A point of the route. The robot turns in place to face the next waypoint, drives there in a
/// straight line, then stops for stop_s seconds and turns spin_deg in place (both optional).
struct Waypoint {
    double x = 0, y = 0;  // m
    double stop_s = 0;    // s standing still on arrival
    double spin_deg = 0;  // deg of extra rotation in place on arrival (sign = direction)
};

struct World {
    std::string name;
    mrpt::maps::COccupancyGridMap2D grid;
    std::vector<Waypoint> route;  // the first waypoint is the start pose (facing the second)
};

/// Built-in worlds (deterministic): "office" — 24 x 14 m, rooms, doorways, pillars and chair legs,
/// a loop with stops and rotations in place; "corridor" — a 60 m featureless corridor driven
/// down and back (the paper's stated weak spot).
World makeWorld(const std::string& name);
/// The names makeWorld accepts.
std::vector<std::string> worldNames();

/// A world from an MRPT .gridmap(.gz) file and a route file with lines "x y [stop_s [spin_deg]]".
World loadWorld(const std::string& gridmap, const std::string& route_file);

}  // namespace kfd
