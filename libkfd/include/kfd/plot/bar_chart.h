// Grouped bar charts with error bars, drawn with MRPT's 2D canvas (no OpenGL, no display).
#pragma once

#include <mrpt/img/CImage.h>

#include <string>
#include <vector>

#include "kfd/pipeline/error.h"

namespace kfd {

/// A chart or figure that cannot be drawn from its input (shapes, values), or a chart CSV that
/// cannot be read (path and line in the message).
class PlotError : public Error {
  public:
    using Error::Error;
};

struct BarChart {
    std::string title, y_label;
    std::vector<std::string> groups;          // x categories (e.g. datasets)
    std::vector<std::string> series;          // bars per group (e.g. modes)
    std::vector<std::vector<double>> values;  // [group][series]; NaN = no bar
    std::vector<std::vector<double>> errors;  // same shape, optional (+- error bar)
    bool log_y = false;
    int width = 1000, height = 500;  // px: kMinSidePx to kMaxSidePx, at most kMaxPixels

    static constexpr int kMinSidePx = 200, kMaxSidePx = 10000;
    static constexpr double kMaxPixels = 40.0e6;

    /// The bars fill the plot area; the legend under it wraps to the image's width. Throws
    /// PlotError when the shapes do not match, a log axis has a value <= 0 or the size is outside
    /// the budget.
    mrpt::img::CImage render() const;
    /// The colour of series s (R, G, B), shared by bars and legend.
    static mrpt::img::TColor seriesColour(std::size_t s);
};

/// Reads "group,series,value[,error]" rows (header line first) into a chart, keeping first-seen
/// order of groups and series. Throws PlotError on malformed input.
BarChart readBarChartCsv(const std::string& path);

}  // namespace kfd
