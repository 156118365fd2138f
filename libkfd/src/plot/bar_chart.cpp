#include "kfd/plot/bar_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace kfd {

mrpt::img::TColor BarChart::seriesColour(std::size_t s) {
    static const mrpt::img::TColor c[] = {{31, 119, 180},  {255, 127, 14},  {44, 160, 44},
                                          {214, 39, 40},   {148, 103, 189}, {140, 86, 75},
                                          {227, 119, 194}, {127, 127, 127}};
    return c[s % 8];
}

namespace {

// The plot area and the value axis: decades on a log axis, 0..a nice maximum otherwise.
struct Axes {
    int left = 80, right = 0, top = 40, bottom = 0;
    double y0 = 0.0, y1 = 1.0;
    bool log_y = false;

    double ty(double v) const { return log_y ? std::log10(v) : v; }
    int py(double v) const {
        const double f = (ty(std::max(v, y0)) - ty(y0)) / (ty(y1) - ty(y0));
        return static_cast<int>(std::lround(bottom - f * (bottom - top)));
    }
};

// The values' range (with their error bars); PlotError on a row of the wrong size or a value
// <= 0 on a log axis.
std::pair<double, double> valueRange(const BarChart& c) {
    double lo = 1e300, hi = -1e300;
    for (std::size_t g = 0; g < c.groups.size(); ++g) {
        if (c.values[g].size() != c.series.size())
            throw PlotError("bar chart: a row has the wrong number of values");
        for (std::size_t s = 0; s < c.series.size(); ++s) {
            const double v = c.values[g][s];
            if (std::isnan(v)) continue;
            const double e = c.errors.empty() ? 0.0 : c.errors[g][s];
            if (c.log_y && v <= 0) throw PlotError("bar chart: value <= 0 on a log axis");
            lo = std::min(lo, v);
            hi = std::max(hi, v + (std::isnan(e) ? 0.0 : e));
        }
    }
    if (hi < lo) lo = 0, hi = 1;
    return {lo, hi};
}

Axes axesFor(const BarChart& c) {
    Axes ax;
    ax.right = c.width - 20;
    ax.bottom = c.height - 90;
    ax.log_y = c.log_y;
    const auto [lo, hi] = valueRange(c);
    if (c.log_y) {
        ax.y0 = std::pow(10.0, std::floor(std::log10(lo)));
        ax.y1 = std::pow(10.0, std::ceil(std::log10(hi)));
        if (ax.y1 <= ax.y0) ax.y1 = ax.y0 * 10;
    } else {
        ax.y0 = 0.0;
        const double mag = std::pow(10.0, std::floor(std::log10(std::max(hi, 1e-12))));
        ax.y1 = std::ceil(hi / mag) * mag;
    }
    return ax;
}

const mrpt::img::TColor kBlack(0, 0, 0), kLight(225, 225, 225);

// Title, y label, grid lines with their tick labels, and the two axes.
void drawAxes(mrpt::img::CImage& img, const BarChart& c, const Axes& ax) {
    img.selectTextFont("9x15");
    img.textOut(ax.left, 10, c.title, kBlack);
    img.selectTextFont("6x13");
    img.textOut(8, ax.top - 16, c.y_label, kBlack);
    std::vector<double> ticks;
    if (ax.log_y)
        for (double t = ax.y0; t <= ax.y1 * 1.0001; t *= 10) ticks.push_back(t);
    else
        for (int k = 0; k <= 5; ++k) ticks.push_back(ax.y0 + (ax.y1 - ax.y0) * k / 5.0);
    char buf[32];
    for (const double t : ticks) {
        img.line(ax.left, ax.py(t), ax.right, ax.py(t), kLight, 1);
        std::snprintf(buf, sizeof(buf), "%g", t);
        img.textOut(8, ax.py(t) - 6, buf, kBlack);
    }
    img.line(ax.left, ax.top, ax.left, ax.bottom, kBlack, 1);
    img.line(ax.left, ax.bottom, ax.right, ax.bottom, kBlack, 1);
}

// One group of bars per row, its label under the axis (cut to the group's width), error bars.
void drawBars(mrpt::img::CImage& img, const BarChart& c, const Axes& ax) {
    const double gw = double(ax.right - ax.left) / std::max<std::size_t>(1, c.groups.size());
    const double bw = gw * 0.8 / std::max<std::size_t>(1, c.series.size());
    for (std::size_t g = 0; g < c.groups.size(); ++g) {
        const int gx = ax.left + static_cast<int>(g * gw + 0.1 * gw);
        // 6x13 font: 6 px per character; cut labels to the group's width.
        const std::size_t fit = static_cast<std::size_t>(std::max(1.0, 0.95 * gw / 6.0));
        img.textOut(gx, ax.bottom + 6, c.groups[g].substr(0, fit), kBlack);
        for (std::size_t s = 0; s < c.series.size(); ++s) {
            const double v = c.values[g][s];
            if (std::isnan(v)) continue;
            const int x0 = gx + static_cast<int>(s * bw),
                      x1 = gx + static_cast<int>((s + 1) * bw) - 2;
            img.filledRectangle(x0, ax.py(v), x1, ax.bottom - 1, BarChart::seriesColour(s));
            const double e = c.errors.empty() ? 0.0 : c.errors[g][s];
            if (e > 0 && !std::isnan(e)) {
                const int xm = (x0 + x1) / 2;
                img.line(xm, ax.py(v + e), xm, ax.py(std::max(v - e, ax.log_y ? ax.y0 : 0.0)),
                         kBlack, 1);
                img.line(xm - 3, ax.py(v + e), xm + 3, ax.py(v + e), kBlack, 1);
            }
        }
    }
}

// The legend under the axis, in rows that fit the image's width.
void drawLegend(mrpt::img::CImage& img, const BarChart& c, const Axes& ax) {
    int lx = ax.left, ly = ax.bottom + 30;
    for (std::size_t s = 0; s < c.series.size(); ++s) {
        const int w = 24 + 7 * static_cast<int>(c.series[s].size());
        if (lx > ax.left && lx + w > c.width) lx = ax.left, ly += 18;
        img.filledRectangle(lx, ly, lx + 12, ly + 12, BarChart::seriesColour(s));
        img.textOut(lx + 16, ly, c.series[s], kBlack);
        lx += w;
    }
}

}  // namespace

mrpt::img::CImage BarChart::render() const {
    if (values.size() != groups.size()) throw PlotError("bar chart: rows != groups");
    if (std::min(width, height) < kMinSidePx || std::max(width, height) > kMaxSidePx ||
        double(width) * height > kMaxPixels)
        throw PlotError("bar chart: size " + std::to_string(width) + " x " +
                        std::to_string(height) + " px is outside " + std::to_string(kMinSidePx) +
                        ".." + std::to_string(kMaxSidePx) +
                        " px a side or above 40 million "
                        "pixels");
    const Axes ax = axesFor(*this);
    mrpt::img::CImage img(width, height, mrpt::img::CH_RGB);
    img.filledRectangle(0, 0, width - 1, height - 1, mrpt::img::TColor(255, 255, 255));
    drawAxes(img, *this, ax);
    drawBars(img, *this, ax);
    drawLegend(img, *this, ax);
    return img;
}

BarChart readBarChartCsv(const std::string& path) {
    std::ifstream f(path);
    if (!f) throw PlotError("cannot open " + path);
    BarChart c;
    std::string line;
    std::getline(f, line);  // header
    struct Row {
        std::size_t g, s;
        double v, e;
    };
    std::vector<Row> rows;
    std::size_t lineno = 1;
    auto index = [](std::vector<std::string>& names, const std::string& n) {
        const auto it = std::find(names.begin(), names.end(), n);
        if (it != names.end()) return static_cast<std::size_t>(it - names.begin());
        names.push_back(n);
        return names.size() - 1;
    };
    while (std::getline(f, line)) {
        ++lineno;
        if (line.empty()) continue;
        std::stringstream ss(line);
        std::string g, s, v, e;
        if (!std::getline(ss, g, ',') || !std::getline(ss, s, ',') || !std::getline(ss, v, ','))
            throw PlotError(path + ":" + std::to_string(lineno) + ": expected group,series,value");
        std::getline(ss, e, ',');
        try {
            rows.push_back({index(c.groups, g), index(c.series, s), std::stod(v),
                            e.empty() ? 0.0 : std::stod(e)});
        } catch (const std::exception&) {
            throw PlotError(path + ":" + std::to_string(lineno) + ": not a number");
        }
    }
    c.values.assign(c.groups.size(), std::vector<double>(c.series.size(), std::nan("")));
    c.errors.assign(c.groups.size(), std::vector<double>(c.series.size(), 0.0));
    for (const auto& r : rows) {
        c.values[r.g][r.s] = r.v;
        c.errors[r.g][r.s] = r.e;
    }
    return c;
}

}  // namespace kfd
