#include "kfd/plot/bar_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace kfd {

mrpt::img::TColor BarChart::seriesColour(std::size_t s) {
    static const mrpt::img::TColor c[] = {{31, 119, 180},  {255, 127, 14},  {44, 160, 44},
                                          {214, 39, 40},   {148, 103, 189}, {140, 86, 75},
                                          {227, 119, 194}, {127, 127, 127}};
    return c[s % 8];
}

mrpt::img::CImage BarChart::render() const {
    if (values.size() != groups.size()) throw PlotError("bar chart: rows != groups");
    if (std::min(width, height) < kMinSidePx || std::max(width, height) > kMaxSidePx ||
        double(width) * height > kMaxPixels)
        throw PlotError("bar chart: size " + std::to_string(width) + " x " +
                        std::to_string(height) + " px is outside " + std::to_string(kMinSidePx) +
                        ".." + std::to_string(kMaxSidePx) +
                        " px a side or above 40 million "
                        "pixels");
    double lo = 1e300, hi = -1e300;
    for (std::size_t g = 0; g < groups.size(); ++g) {
        if (values[g].size() != series.size())
            throw PlotError("bar chart: a row has the wrong number of values");
        for (std::size_t s = 0; s < series.size(); ++s) {
            const double v = values[g][s];
            if (std::isnan(v)) continue;
            const double e = errors.empty() ? 0.0 : errors[g][s];
            if (log_y && v <= 0) throw PlotError("bar chart: value <= 0 on a log axis");
            lo = std::min(lo, v);
            hi = std::max(hi, v + (std::isnan(e) ? 0.0 : e));
        }
    }
    if (hi < lo) lo = 0, hi = 1;
    // Axis range: decades on a log axis, 0..nice max otherwise.
    double y0, y1;
    if (log_y) {
        y0 = std::pow(10.0, std::floor(std::log10(lo)));
        y1 = std::pow(10.0, std::ceil(std::log10(hi)));
        if (y1 <= y0) y1 = y0 * 10;
    } else {
        y0 = 0.0;
        const double mag = std::pow(10.0, std::floor(std::log10(std::max(hi, 1e-12))));
        y1 = std::ceil(hi / mag) * mag;
    }
    auto ty = [&](double v) { return log_y ? std::log10(v) : v; };

    mrpt::img::CImage img(width, height, mrpt::img::CH_RGB);
    img.filledRectangle(0, 0, width - 1, height - 1, mrpt::img::TColor(255, 255, 255));
    const int left = 80, right = width - 20, top = 40, bottom = height - 90;
    auto py = [&](double v) {
        const double f = (ty(std::max(v, y0)) - ty(y0)) / (ty(y1) - ty(y0));
        return static_cast<int>(std::lround(bottom - f * (bottom - top)));
    };
    const mrpt::img::TColor black(0, 0, 0), light(225, 225, 225);
    img.selectTextFont("9x15");
    img.textOut(left, 10, title, black);
    img.selectTextFont("6x13");
    img.textOut(8, top - 16, y_label, black);
    // Grid lines and tick labels.
    std::vector<double> ticks;
    if (log_y)
        for (double t = y0; t <= y1 * 1.0001; t *= 10) ticks.push_back(t);
    else
        for (int k = 0; k <= 5; ++k) ticks.push_back(y0 + (y1 - y0) * k / 5.0);
    char buf[32];
    for (const double t : ticks) {
        img.line(left, py(t), right, py(t), light, 1);
        std::snprintf(buf, sizeof(buf), "%g", t);
        img.textOut(8, py(t) - 6, buf, black);
    }
    img.line(left, top, left, bottom, black, 1);
    img.line(left, bottom, right, bottom, black, 1);
    // Bars.
    const double gw = double(right - left) / std::max<std::size_t>(1, groups.size());
    const double bw = gw * 0.8 / std::max<std::size_t>(1, series.size());
    for (std::size_t g = 0; g < groups.size(); ++g) {
        const int gx = left + static_cast<int>(g * gw + 0.1 * gw);
        // 6x13 font: 6 px per character; cut labels to the group's width.
        const std::size_t fit = static_cast<std::size_t>(std::max(1.0, 0.95 * gw / 6.0));
        img.textOut(gx, bottom + 6, groups[g].substr(0, fit), black);
        for (std::size_t s = 0; s < series.size(); ++s) {
            const double v = values[g][s];
            if (std::isnan(v)) continue;
            const int x0 = gx + static_cast<int>(s * bw),
                      x1 = gx + static_cast<int>((s + 1) * bw) - 2;
            img.filledRectangle(x0, py(v), x1, bottom - 1, seriesColour(s));
            const double e = errors.empty() ? 0.0 : errors[g][s];
            if (e > 0 && !std::isnan(e)) {
                const int xm = (x0 + x1) / 2;
                img.line(xm, py(v + e), xm, py(std::max(v - e, log_y ? y0 : 0.0)), black, 1);
                img.line(xm - 3, py(v + e), xm + 3, py(v + e), black, 1);
            }
        }
    }
    // Legend under the axis, in rows that fit the image's width.
    int lx = left, ly = bottom + 30;
    for (std::size_t s = 0; s < series.size(); ++s) {
        const int w = 24 + 7 * static_cast<int>(series[s].size());
        if (lx > left && lx + w > width) lx = left, ly += 18;
        img.filledRectangle(lx, ly, lx + 12, ly + 12, seriesColour(s));
        img.textOut(lx + 16, ly, series[s], black);
        lx += w;
    }
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
