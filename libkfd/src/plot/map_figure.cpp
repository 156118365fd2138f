#include "kfd/plot/map_figure.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "kfd/core/format.h"
#include "kfd/eval/ate.h"

namespace kfd {
namespace {

using mrpt::img::TColor;

void path(mrpt::img::CImage& img, const mrpt::maps::COccupancyGridMap2D& g, const Trajectory& t,
          const TColor& c, unsigned width) {
    for (std::size_t i = 1; i < t.size(); ++i) {
        const auto a = mapFigurePixel(g, t[i - 1].pose.x, t[i - 1].pose.y);
        const auto b = mapFigurePixel(g, t[i].pose.x, t[i].pose.y);
        img.line(a.first, a.second, b.first, b.second, c, width);
    }
}

}  // namespace

std::pair<int, int> mapFigurePixel(const mrpt::maps::COccupancyGridMap2D& g, double x, double y) {
    // getAsImage(verticalFlip = true) puts the grid's last row (largest y) at the top. A point
    // far outside the image (a track lost far away, NaN) is clamped well outside it: lines
    // towards it are clipped by the canvas, and no double is cast beyond an int's range.
    const double res = g.getResolution();
    auto cell = [](double v) {
        constexpr double kFar = 1.0e6;  // pixels; images are at most a few thousand wide
        return static_cast<int>(std::isnan(v) ? -kFar : std::clamp(std::floor(v), -kFar, kFar));
    };
    const int col = cell((x - g.getXMin()) / res);
    const int row = static_cast<int>(g.getSizeY()) - 1 - cell((y - g.getYMin()) / res);
    return {col, row};
}

mrpt::img::CImage renderMapFigure(const MapFigureInput& in) {
    if (!in.grid) throw PlotError("map figure: no grid");
    const auto& g = *in.grid;
    mrpt::img::CImage img;
    g.getAsImage(img, true, true);  // +y up, RGB

    Trajectory gt = in.ground_truth, odo = in.odometry;
    if (gt.size() >= 2 && in.estimate.size() >= 2) {  // gt ~ T (+) est: bring gt to the map frame
        Trajectory sorted_gt = gt;
        sortByTime(sorted_gt);
        const auto ate = computeAte(in.estimate, sorted_gt, 0.05);
        const Pose2D inv = inverse(ate.alignment);
        for (auto& p : gt) p.pose = compose(inv, p.pose);
    }
    if (!odo.empty() && !in.estimate.empty()) {  // start the odometry where the estimate starts
        const Pose2D t = compose(in.estimate.front().pose, inverse(odo.front().pose));
        for (auto& p : odo) p.pose = compose(t, p.pose);
    }
    const TColor grey(150, 150, 150), green(30, 160, 60), blue(30, 90, 220), navy(10, 20, 90),
        black(0, 0, 0), orange(240, 130, 0);
    path(img, g, odo, grey, 1);
    path(img, g, gt, green, 5);  // wide: stays visible under an accurate estimate
    path(img, g, in.estimate, blue, 2);
    for (const auto k : in.corridor) {  // under the keyframe dots
        if (k >= in.estimate.size()) continue;
        const auto p = mapFigurePixel(g, in.estimate[k].pose.x, in.estimate[k].pose.y);
        img.filledRectangle(p.first - 2, p.second - 2, p.first + 2, p.second + 2, orange);
    }
    for (const auto k : in.keyframes) {
        if (k >= in.estimate.size()) continue;
        const auto p = mapFigurePixel(g, in.estimate[k].pose.x, in.estimate[k].pose.y);
        img.filledRectangle(p.first - 1, p.second - 1, p.first + 1, p.second + 1, navy);
    }

    // Legend, title and a 1 m scale bar.
    img.selectTextFont("9x15");
    int y = 8;
    if (!in.title.empty()) {
        img.textOut(8, y, in.title, black);
        y += 20;
    }
    auto entry = [&](const TColor& c, const std::string& label) {
        img.filledRectangle(8, y + 4, 28, y + 8, c);
        img.textOut(34, y, label, black);
        y += 18;
    };
    entry(blue, "estimate (dots: keyframes)");
    if (!gt.empty()) entry(green, "ground truth (aligned)");
    if (!odo.empty()) entry(grey, "odometry");
    if (!in.corridor.empty()) entry(orange, "corridor switch: degenerate scans");
    // Scale bar: 1, 2 or 5 times a power of ten metres, at least 20 pixels long.
    double metres = 1.0;
    for (int k = 0; metres / g.getResolution() < 19.5 && k < 60; ++k)  // 0.05f is > 0.05
        metres *= (k % 3 == 1) ? 2.5 : 2.0;                            // 1, 2, 5, 10, 20, 50, ...
    const int bar = static_cast<int>(std::lround(metres / g.getResolution()));
    const int by = static_cast<int>(img.getHeight()) - 12;
    img.line(8, by, 8 + bar, by, black, 2);
    img.textOut(12 + bar, by - 8, format("%g m", metres), black);
    return img;
}

}  // namespace kfd
