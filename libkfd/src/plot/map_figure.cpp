#include "kfd/plot/map_figure.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

#include "kfd/eval/ate.h"
#include "kfd/pipeline/format.h"

namespace kfd {
namespace {

using mrpt::img::TColor;
using Grid = mrpt::maps::COccupancyGridMap2D;

// Poses farther than this from the origin (m) are drawn (clamped, off the image) but do not
// stretch the figure's bounds: their difference would overflow a double's range.
constexpr double kFarM = 1.0e15;

bool usable(const Pose2D& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::abs(p.x) < kFarM &&
           std::abs(p.y) < kFarM;
}

// The bounds of what is drawn (m), grown point by point.
struct Bounds {
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    bool empty() const { return x1 < x0; }
    void add(double x, double y) {
        x0 = std::min(x0, x), x1 = std::max(x1, x);
        y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
};

// A trajectory is drawn when it has a segment between two usable poses.
bool hasSegment(const Trajectory& t) {
    for (std::size_t i = 1; i < t.size(); ++i)
        if (usable(t[i - 1].pose) && usable(t[i].pose)) return true;
    return false;
}

void addPath(Bounds& b, const Trajectory& t) {
    for (const auto& p : t)
        if (usable(p.pose)) b.add(p.pose.x, p.pose.y);
}

// The indices into `t` of usable poses among `idx`.
std::vector<std::size_t> drawable(const std::vector<std::size_t>& idx, const Trajectory& t) {
    std::vector<std::size_t> out;
    for (const auto k : idx)
        if (k < t.size() && usable(t[k].pose)) out.push_back(k);
    return out;
}

void path(mrpt::img::CImage& img, const MapFigureFrame& f, const Trajectory& t, const TColor& c,
          unsigned width) {
    for (std::size_t i = 1; i < t.size(); ++i) {
        if (!usable(t[i - 1].pose) || !usable(t[i].pose)) continue;
        const auto a = f.pixel(t[i - 1].pose.x, t[i - 1].pose.y);
        const auto b = f.pixel(t[i].pose.x, t[i].pose.y);
        img.line(a.first, a.second, b.first, b.second, c, width);
    }
}

// The grid into the map part of `img`: each pixel shows the most occupied known cell it covers
// (the darkest, as getAsImage draws it: white free, black occupied), unknown grey otherwise.
void drawGrid(mrpt::img::CImage& img, const Grid& g, const MapFigureFrame& f) {
    const auto& raw = g.getRawMap();
    const int nx = static_cast<int>(g.getSizeX()), ny = static_cast<int>(g.getSizeY());
    const double res = g.getResolution(), gx = g.getXMin(), gy = g.getYMin();
    const std::uint8_t unknown = Grid::l2p_255(0);
    // The cell range [first, last) under [a, b) metres, clipped to [0, n).
    auto cells = [res](double a, double b, double origin, int n) {
        const double lo = std::floor((a - origin) / res + 1e-9),
                     hi = std::ceil((b - origin) / res - 1e-9);
        return std::pair<int, int>{static_cast<int>(std::clamp(lo, 0.0, double(n))),
                                   static_cast<int>(std::clamp(hi, 0.0, double(n)))};
    };
    std::vector<std::pair<int, int>> cols(static_cast<std::size_t>(f.width));
    for (int c = 0; c < f.width; ++c)
        cols[c] =
            cells(f.x_min + c * f.metres_per_pixel, f.x_min + (c + 1) * f.metres_per_pixel, gx, nx);
    for (int r = 0; r < f.height; ++r) {
        const auto rows =
            cells(f.y_max - (r + 1) * f.metres_per_pixel, f.y_max - r * f.metres_per_pixel, gy, ny);
        for (int c = 0; c < f.width; ++c) {
            int v = 256;
            for (int cy = rows.first; cy < rows.second; ++cy)
                for (int cx = cols[c].first; cx < cols[c].second; ++cx) {
                    const auto l = raw[static_cast<std::size_t>(cy) * nx + cx];
                    if (l != 0) v = std::min<int>(v, Grid::l2p_255(l));
                }
            const auto grey = static_cast<std::uint8_t>(v > 255 ? unknown : v);
            auto* p = img.ptr<std::uint8_t>(c, f.top + r);
            p[0] = p[1] = p[2] = grey;
        }
    }
}

struct Layer {
    MapFigureLayer text;
    TColor colour;
    bool dot = false;  // legend swatch: a dot, not a line
    bool legend = true;
};

constexpr int kCharPx = 9, kTitleRowPx = 20, kEntryRowPx = 18, kScaleRowPx = 22, kPadPx = 8;

}  // namespace

std::optional<CellBox> knownCellBox(const Grid& g) {
    const auto& raw = g.getRawMap();
    const int nx = static_cast<int>(g.getSizeX()), ny = static_cast<int>(g.getSizeY());
    CellBox b{nx, ny, -1, -1};
    for (int cy = 0; cy < ny; ++cy)
        for (int cx = 0; cx < nx; ++cx)
            if (raw[static_cast<std::size_t>(cy) * nx + cx] != 0) {
                b.x0 = std::min(b.x0, cx), b.x1 = std::max(b.x1, cx);
                b.y0 = std::min(b.y0, cy), b.y1 = std::max(b.y1, cy);
            }
    if (b.x1 < 0) return std::nullopt;
    return b;
}

std::pair<int, int> MapFigureFrame::pixel(double x, double y) const {
    auto at = [](double v) {
        constexpr double kFar = 1.0e6;  // pixels; images are at most a few thousand wide
        return static_cast<int>(std::isnan(v) ? -kFar : std::clamp(std::floor(v), -kFar, kFar));
    };
    return {at((x - x_min) / metres_per_pixel), top + at((y_max - y) / metres_per_pixel)};
}

namespace {

// `t` started where the estimate starts (its first pose on the estimate's first pose).
Trajectory fromEstimateStart(const MapFigureInput& in, Trajectory t) {
    if (t.empty() || in.estimate.empty()) return t;
    const Pose2D to = compose(in.estimate.front().pose, inverse(t.front().pose));
    for (auto& p : t) p.pose = compose(to, p.pose);
    return t;
}

// The ground truth brought to the estimate's frame (gt ~ T (+) est).
void alignToEstimate(const MapFigureInput& in, Trajectory& gt) {
    gt = in.ground_truth;
    if (gt.size() >= 2 && in.estimate.size() >= 2) {
        Trajectory sorted_gt = gt;
        sortByTime(sorted_gt);
        const auto ate = computeAte(in.estimate, sorted_gt, 0.05);
        const Pose2D inv = inverse(ate.alignment);
        for (auto& p : gt) p.pose = compose(inv, p.pose);
    }
}

const TColor kGrey(150, 150, 150), kGreen(30, 160, 60), kBlue(30, 90, 220), kNavy(10, 20, 90),
    kBlack(0, 0, 0), kOrange(240, 130, 0), kPurple(160, 40, 180), kRed(220, 0, 0);

// The layers drawn (in legend order) and their bounds, with the margin: nothing else sets the
// figure's extent.
Bounds layersAndBounds(const MapFigureInput& in, const Trajectory& gt, const Trajectory& odo,
                       const Trajectory& track, const std::vector<std::size_t>& keyframes,
                       const std::vector<std::size_t>& corridor,
                       const std::vector<std::size_t>& lost, std::vector<Layer>& layers) {
    const auto& g = *in.grid;
    const double res = g.getResolution();
    Bounds b;
    if (const auto cells = knownCellBox(g)) {
        layers.push_back({{"occupancy map", "white free, black occupied"}, kBlack, false, false});
        b.add(g.getXMin() + cells->x0 * res, g.getYMin() + cells->y0 * res);
        b.add(g.getXMin() + (cells->x1 + 1) * res, g.getYMin() + (cells->y1 + 1) * res);
    }
    const bool draw_est = hasSegment(in.estimate), draw_gt = hasSegment(gt),
               draw_odo = hasSegment(odo), draw_track = hasSegment(track);
    if (draw_est) layers.push_back({{"estimate", "blue"}, kBlue});
    if (!keyframes.empty()) layers.push_back({{"keyframes", "navy dots"}, kNavy, true});
    if (draw_gt) layers.push_back({{"ground truth, aligned to the estimate", "green"}, kGreen});
    if (draw_odo) layers.push_back({{"odometry from the estimate's start", "grey"}, kGrey});
    if (draw_track)
        layers.push_back({{"kfd's scan track from the estimate's start", "purple"}, kPurple});
    if (!corridor.empty())
        layers.push_back({{"scans the corridor switch found degenerate", "orange"}, kOrange, true});
    if (!lost.empty())
        layers.push_back({{"suspected lost track begins", "red crosses"}, kRed, true});
    if (draw_est || !keyframes.empty() || !corridor.empty()) addPath(b, in.estimate);
    if (draw_gt) addPath(b, gt);
    if (draw_odo) addPath(b, odo);
    if (draw_track) addPath(b, track);
    if (b.empty()) b.add(0.5 * (g.getXMin() + g.getXMax()), 0.5 * (g.getYMin() + g.getYMax()));
    const double margin = std::max(in.margin_m, 0.0) + 0.5 * res;
    b.x0 -= margin, b.y0 -= margin, b.x1 += margin, b.y1 += margin;
    return b;
}

// The legend band above the map: its title (a title wider than the budget is cut with "...":
// it never widens the image beyond it), height and width; PlotError when the budget cannot
// hold it.
struct Band {
    std::string title;
    int height = 0, width = 0;
};
Band legendBand(const MapFigureInput& in, const std::vector<Layer>& layers) {
    Band band;
    band.title = in.title;
    const std::size_t title_chars = static_cast<std::size_t>(
        std::max(4, (std::min(in.max_side_px, 1 << 20) - 2 * kPadPx) / kCharPx));
    if (band.title.size() > title_chars) band.title = band.title.substr(0, title_chars - 3) + "...";
    band.height = kPadPx + kScaleRowPx + (band.title.empty() ? 0 : kTitleRowPx);
    band.width = 200;  // the scale bar and its label
    if (!band.title.empty())
        band.width =
            std::max(band.width, 2 * kPadPx + kCharPx * static_cast<int>(band.title.size()));
    for (const auto& l : layers) {
        if (!l.legend) continue;
        band.height += kEntryRowPx;
        band.width =
            std::max(band.width, 34 + kPadPx + kCharPx * static_cast<int>(l.text.name.size()));
    }
    const double side = in.max_side_px;
    if (band.width > side || band.height + 1 > side ||
        double(band.width) * (band.height + 1) > in.max_pixels)
        throw PlotError(
            format("map figure: a budget of %d px a side and %.0f pixels is too "
                   "small for the legend (%d x %d px)",
                   in.max_side_px, in.max_pixels, band.width, band.height + 1));
    return band;
}

// The frame: the cell size drawn (the grid's, coarser until the whole image fits the
// budget), the map's corner and size in pixels.
MapFigureFrame frameFor(const MapFigureInput& in, const Bounds& b, const Band& band) {
    const auto& g = *in.grid;
    const double res = g.getResolution();
    const double side = in.max_side_px;
    const double w_m = b.x1 - b.x0, h_m = b.y1 - b.y0;
    double mpp = std::max({res, w_m / side, h_m / (side - band.height)});
    auto size = [&](double m) {
        const int w = std::max(1, static_cast<int>(std::ceil(w_m / m - 1e-9)));
        const int h = std::max(1, static_cast<int>(std::ceil(h_m / m - 1e-9)));
        return std::pair<int, int>{w, h};
    };
    for (int k = 0; k < 10000; ++k) {  // the area shrinks with mpp^2 down to the legend's
        const auto [w, h] = size(mpp);
        if (std::max(w, band.width) <= side && h + band.height <= side &&
            double(std::max(w, band.width)) * (h + band.height) <= in.max_pixels)
            break;
        mpp *= 1.01;
    }
    MapFigureFrame f;
    f.metres_per_pixel = mpp;
    f.x_min = b.x0, f.y_max = b.y1;
    if (mpp == res) {  // one cell a pixel: put the pixels on the cells
        f.x_min = g.getXMin() + std::floor((b.x0 - g.getXMin()) / res) * res;
        f.y_max = g.getYMin() + std::ceil((b.y1 - g.getYMin()) / res) * res;
    }
    std::tie(f.width, f.height) = size(mpp);
    f.top = band.height;
    return f;
}

// Title, legend and scale bar in the band (the scale bar: 1, 2 or 5 times a power of ten
// metres, at least 20 pixels long).
void drawBand(MapFigure& fig, const Band& band, const std::vector<Layer>& layers) {
    auto& img = fig.image;
    img.selectTextFont("9x15");
    int y = kPadPx;
    if (!band.title.empty()) {
        img.textOut(kPadPx, y, band.title, kBlack);
        y += kTitleRowPx;
    }
    for (const auto& l : layers) {
        fig.layers.push_back(l.text);
        if (!l.legend) continue;
        if (l.dot)
            img.filledRectangle(16, y + 4, 20, y + 8, l.colour);
        else
            img.filledRectangle(8, y + 4, 28, y + 8, l.colour);
        img.textOut(34, y, l.text.name, kBlack);
        y += kEntryRowPx;
    }
    const double mpp = fig.frame.metres_per_pixel;
    double metres = 1.0;
    for (int k = 0; metres / mpp < 19.5 && k < 1000; ++k)  // 0.05f is > 0.05
        metres *= (k % 3 == 1) ? 2.5 : 2.0;                // 1, 2, 5, 10, 20, 50, ...
    fig.scale_bar_m = metres;
    fig.scale_bar_px = static_cast<int>(std::lround(metres / mpp));
    fig.scale_bar_row = y + 8;
    img.line(kPadPx, fig.scale_bar_row, kPadPx + fig.scale_bar_px, fig.scale_bar_row, kBlack, 2);
    img.textOut(12 + kPadPx + fig.scale_bar_px, y, format("%g m", metres), kBlack);
}

// Squares of side 2 h + 1 px at the estimate's poses `at`.
void squares(mrpt::img::CImage& img, const MapFigureFrame& f, const Trajectory& est,
             const std::vector<std::size_t>& at, int h, const TColor& c) {
    for (const auto k : at) {
        const auto p = f.pixel(est[k].pose.x, est[k].pose.y);
        img.filledRectangle(p.first - h, p.second - h, p.first + h, p.second + h, c);
    }
}

// Every layer, from the bottom up, each narrower than the one below: where they coincide (an
// accurate estimate on the ground truth, odometry that needed no correction) each still shows.
void drawLayers(mrpt::img::CImage& img, const MapFigureFrame& f, const MapFigureInput& in,
                const Trajectory& gt, const Trajectory& odo, const Trajectory& track,
                const std::vector<std::size_t>& keyframes, const std::vector<std::size_t>& corridor,
                const std::vector<std::size_t>& lost) {
    path(img, f, gt, kGreen, 7);
    path(img, f, track, kPurple, 5);
    squares(img, f, in.estimate, corridor, 3, kOrange);
    squares(img, f, in.estimate, keyframes, 2, kNavy);
    path(img, f, in.estimate, kBlue, 3);
    path(img, f, odo, kGrey, 1);
    for (const auto k : lost) {  // a cross of 15 px, on top of everything
        const auto p = f.pixel(in.estimate[k].pose.x, in.estimate[k].pose.y);
        img.line(p.first - 7, p.second - 7, p.first + 7, p.second + 7, kRed, 3);
        img.line(p.first - 7, p.second + 7, p.first + 7, p.second - 7, kRed, 3);
    }
}

}  // namespace

MapFigure renderMapFigure(const MapFigureInput& in) {
    if (!in.grid) throw PlotError("map figure: no grid");
    Trajectory gt;
    alignToEstimate(in, gt);
    const Trajectory odo = fromEstimateStart(in, in.odometry);
    const Trajectory track = fromEstimateStart(in, in.track);
    const auto keyframes = drawable(in.keyframes, in.estimate);
    const auto corridor = drawable(in.corridor, in.estimate);
    const auto lost = drawable(in.lost_tracks, in.estimate);
    std::vector<Layer> layers;
    const Bounds b = layersAndBounds(in, gt, odo, track, keyframes, corridor, lost, layers);
    const Band band = legendBand(in, layers);
    MapFigure fig;
    fig.frame = frameFor(in, b, band);
    const auto& f = fig.frame;
    auto& img = fig.image;
    const int img_w = std::max(f.width, band.width);
    img = mrpt::img::CImage(img_w, band.height + f.height, mrpt::img::CH_RGB);
    img.filledRectangle(0, 0, img_w - 1, band.height + f.height - 1, TColor(255, 255, 255));
    drawGrid(img, *in.grid, f);
    drawLayers(img, f, in, gt, odo, track, keyframes, corridor, lost);
    drawBand(fig, band, layers);
    return fig;
}

std::string mapFigureCaption(const std::vector<MapFigureLayer>& layers) {
    std::string s = "map figure:";
    for (std::size_t i = 0; i < layers.size(); ++i)
        s += (i ? ", " : " ") + layers[i].name + " (" + layers[i].colour + ")";
    return layers.empty() ? s + " nothing drawn" : s;
}

}  // namespace kfd
