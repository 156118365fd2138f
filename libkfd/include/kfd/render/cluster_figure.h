// Off-screen figures with OSMesa: a scan's clusters (like the paper's Figure 9).
#pragma once

#include <mrpt/img/CImage.h>

#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "kfd/paper/clusters.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// No off-screen OpenGL context could be created (e.g. OSMesa missing).
class RenderError : public Error {
  public:
    using Error::Error;
};

struct ClusterFigureOptions {
    int width = 800, height = 800;  // px: 16 to 10 000 a side, at most 40 million pixels
    double half_extent_m = 0.0;     // half the visible height (m), centred on the sensor; 0 = fit
                                    // the returns and the sensor, centred on them
    std::string title;              // first line above the legend (e.g. log, scan, counts)
    double ring_r_max = 0.0;        // draw t faint equal-area ring boundaries up to this (m)
    std::size_t rings = 5;          // t
    float point_size = 4.0f;        // px
};

/// Renders, top-down with +x right and +y up: each kept cluster in its own colour, removed
/// points (invalid in `scan` but labelled in `clusters`, or flagged noise) in red and larger, the
/// ring boundaries faintly, the sensor at the origin, a 1 m grid and a 1 m scale bar (bottom
/// left), the title and the legend. Without an extent the view is the smallest square (or the
/// image's aspect) around the drawn returns and the sensor, with a 5 % margin. Needs no
/// display: the OpenGL context is OSMesa's.
class ClusterFigure {
  public:
    explicit ClusterFigure(const ClusterFigureOptions& opts = {});
    ~ClusterFigure();
    ClusterFigure(const ClusterFigure&) = delete;
    ClusterFigure& operator=(const ClusterFigure&) = delete;

    /// `before` is the scan as it entered the denoiser (its valid beams are drawn); `clusters`
    /// its labels and noise flags. Throws RenderError when rendering fails.
    mrpt::img::CImage render(const Scan& before, const Clusters& clusters);

    /// The image pixel (column, row from the top) where world point (x, y) is drawn in the
    /// last render.
    std::pair<int, int> pixelOf(double x, double y) const;

    /// The colour (R, G, B) used for cluster `label` (noise: 230, 20, 20).
    static std::array<std::uint8_t, 3> colourOf(std::int32_t label, bool noise);

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    ClusterFigureOptions opts_;
    double half_extent_ = 1.0;
    double centre_x_ = 0.0, centre_y_ = 0.0;  // m: the view's centre in the last render
};

}  // namespace kfd
