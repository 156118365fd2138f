// The map figure of an ICP-SLAM run: occupancy grid with trajectories, keyframes and a legend,
// cropped to what it draws and kept within a pixel budget.
#pragma once

#include <mrpt/img/CImage.h>
#include <mrpt/maps/COccupancyGridMap2D.h>

#include <optional>
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
    Trajectory track;         // kfd's scan track (laser odometry): put on the estimate's start too
    std::vector<std::size_t> keyframes;    // indices into `estimate` of scans that were kept
    std::vector<std::size_t> corridor;     // indices into `estimate` of degenerate scans (orange)
    std::vector<std::size_t> lost_tracks;  // indices into `estimate` where a lost track began
    std::string title;  // e.g. mapTitle(): the log, the mode, drop rate, ATE, lost tracks
    /// The pixel budget of the whole image (legend band included): its longest side and its
    /// area. The map is drawn at the grid's cell size unless that exceeds the budget; then each
    /// pixel covers a larger square (and shows the most occupied cell under it).
    int max_side_px = 3000;
    double max_pixels = 6.0e6;
    double margin_m = 1.0;  // around what is drawn
};

/// One thing the figure drew, in legend order: what it is and its colour, in words.
struct MapFigureLayer {
    std::string name;    // e.g. "ground truth, aligned to the estimate"
    std::string colour;  // e.g. "green"
};

/// Where map point (x, y) lands in the figure: column (x - x_min) / metres_per_pixel, row
/// top + (y_max - y) / metres_per_pixel (+y up). Points far outside (a track lost far away,
/// NaN) are clamped well outside the image: lines towards them are clipped by the canvas and
/// no double is cast beyond an int's range.
struct MapFigureFrame {
    double x_min = 0.0, y_max = 0.0, metres_per_pixel = 0.05;
    int top = 0;                // the map's first row (the legend band is above it)
    int width = 0, height = 0;  // of the map part, pixels
    std::pair<int, int> pixel(double x, double y) const;
};

struct MapFigure {
    mrpt::img::CImage image;
    MapFigureFrame frame;
    std::vector<MapFigureLayer> layers;  // exactly what was drawn (the legend's entries)
    double scale_bar_m = 0.0;            // the scale bar's length: metres and pixels, and its row
    int scale_bar_px = 0, scale_bar_row = 0;
};

/// Draws with MRPT's 2D canvas (no OpenGL): the grid's known cells (+y up), then, from the
/// bottom up and each narrower than the one below so that every one shows even where they
/// coincide: the ground truth (green, 7 px), kfd's scan track (purple, 5 px), the scans the
/// corridor switch found degenerate (orange squares), the keyframes (navy squares), the estimate
/// (blue, 3 px), the odometry (grey, 1 px), and red crosses where a lost track began. The map part
/// spans what is drawn (the grid's known cells and the finite poses of the drawn trajectories, plus
/// margin_m; never the grid's empty extent or the origin for its own sake) at the grid's cell size,
/// coarser when that exceeds the budget. Above it, a white band holds the title, the legend (one
/// entry per drawn layer) and a scale bar (1, 2 or 5 times a power of ten metres, at least 20
/// pixels). A trajectory is drawn (and listed) when it has two finite poses, keyframes and
/// degenerate scans when one index is in range, the grid when one cell is known. Throws PlotError
/// without a grid or with a budget too small for the legend.
MapFigure renderMapFigure(const MapFigureInput& in);

/// The smallest box of cells (indices, inclusive) holding every known cell of the grid (log-odds
/// not 0: observed free or occupied); nullopt when no cell is known.
struct CellBox {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
};
std::optional<CellBox> knownCellBox(const mrpt::maps::COccupancyGridMap2D& grid);

/// The figure's alt text / caption: "map figure: " and its layers with their colours, e.g.
/// "map figure: occupancy map (white free, black occupied), estimate (blue)".
std::string mapFigureCaption(const std::vector<MapFigureLayer>& layers);

}  // namespace kfd
