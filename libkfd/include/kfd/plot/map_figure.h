// The map figure of an ICP-SLAM run: occupancy grid with trajectories, keyframes and a legend.
#pragma once

#include <mrpt/img/CImage.h>
#include <mrpt/maps/COccupancyGridMap2D.h>

#include <string>
#include <utility>
#include <vector>

#include "kfd/eval/trajectory.h"
#include "kfd/plot/bar_chart.h"  // PlotError

namespace kfd {

struct MapFigureInput {
    const mrpt::maps::COccupancyGridMap2D* grid = nullptr;  // required
    Trajectory estimate;                                    // map frame
    Trajectory ground_truth;  // any frame: aligned to the estimate (SE(2), least squares)
    Trajectory odometry;      // any frame: its first pose is put on the estimate's first pose
    std::vector<std::size_t> keyframes;  // indices into `estimate` of scans that were kept
    std::vector<std::size_t> corridor;   // indices into `estimate` of degenerate scans (orange)
    std::string title;
};

/// Draws with MRPT's 2D canvas (no OpenGL): the grid (+y up), the odometry (grey), the ground
/// truth (green) and the estimate (blue) with keyframes as small dots and the scans the corridor
/// switch found degenerate in orange, a legend, the title and a
/// scale bar (1, 2 or 5 times a power of ten metres, at least 20 pixels). Throws PlotError
/// without a grid.
mrpt::img::CImage renderMapFigure(const MapFigureInput& in);

/// The pixel (column, row from the top) of map point (x, y) in renderMapFigure's image.
std::pair<int, int> mapFigurePixel(const mrpt::maps::COccupancyGridMap2D& grid, double x, double y);

}  // namespace kfd
