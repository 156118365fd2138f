// kfd/plot/map_figure.h: trajectories land on the right pixels of the grid image.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "kfd/plot/map_figure.h"

namespace {

std::array<std::uint8_t, 3> rgbAt(const mrpt::img::CImage& img, int x, int y) {
    const auto* p = img.ptr<std::uint8_t>(x, y);
    return {p[2], p[1], p[0]};  // CImage stores BGR
}

}  // namespace

TEST(MapFigure, EstimateIsDrawnWherePlusYIsUp) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    // A vertical segment on the +y side, x = 2 m, y from 1 to 3 m.
    for (int k = 0; k <= 20; ++k) in.estimate.push_back({double(k), {2.0, 1.0 + 0.1 * k, 0.0}});
    const auto img = kfd::renderMapFigure(in);
    ASSERT_EQ(img.getWidth(), 200u);
    const auto top = kfd::mapFigurePixel(grid, 2.0, 3.0);
    const auto bottom = kfd::mapFigurePixel(grid, 2.0, 1.0);
    EXPECT_LT(top.second, bottom.second);  // larger y is higher in the image
    EXPECT_GT(top.first, 100);             // +x right of the centre
    const auto mid = kfd::mapFigurePixel(grid, 2.0, 2.0);
    const auto c = rgbAt(img, mid.first, mid.second);
    EXPECT_EQ(c[0], 30);
    EXPECT_EQ(c[1], 90);
    EXPECT_EQ(c[2], 220);
    const auto mirrored = kfd::mapFigurePixel(grid, 2.0, -2.0);  // nothing drawn there
    EXPECT_NE(rgbAt(img, mirrored.first, mirrored.second)[2], 220);
}

TEST(MapFigure, GroundTruthIsAlignedToTheEstimate) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    for (int k = 0; k <= 30; ++k) {
        in.estimate.push_back({double(k), {-3.0 + 0.1 * k, -2.0 + 0.05 * k * (k % 2), 0.0}});
        // The same path in another frame: shifted by (10, 10) and turned 90 degrees.
        const auto& p = in.estimate.back().pose;
        in.ground_truth.push_back({double(k), {10.0 - p.y, 10.0 + p.x, M_PI / 2}});
    }
    const auto img = kfd::renderMapFigure(in);
    // The ground truth (green, drawn wider) shows around the estimate after alignment.
    const auto p = kfd::mapFigurePixel(grid, in.estimate[10].pose.x, in.estimate[10].pose.y);
    bool green = false;
    for (int d = -3; d <= 3; ++d) green |= rgbAt(img, p.first, p.second + d)[1] == 160;
    EXPECT_TRUE(green);
    EXPECT_THROW(kfd::renderMapFigure(kfd::MapFigureInput{}), kfd::PlotError);
}

TEST(MapFigure, DegenerateScansAreMarkedOrange) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    for (int k = 0; k <= 20; ++k) in.estimate.push_back({double(k), {-2.0 + 0.2 * k, 1.0, 0.0}});
    in.corridor = {15};  // x = 1 m
    const auto img = kfd::renderMapFigure(in);
    auto orange = [&](double x) {
        const auto p = kfd::mapFigurePixel(grid, x, 1.0);
        const auto c = rgbAt(img, p.first, p.second - 2);  // beside the blue line
        return c[0] == 240 && c[1] == 130 && c[2] == 0;
    };
    EXPECT_TRUE(orange(1.0));
    EXPECT_FALSE(orange(-1.0));
    in.corridor = {99};  // out of range: ignored
    EXPECT_NO_THROW(kfd::renderMapFigure(in));
}

TEST(MapFigure, PointsFarOutsideTheGridOrNotFiniteAreClampedNotCastBeyondAnInt) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    for (const double v : {1e12, -1e12, 1e300, std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN()}) {
        const auto p = kfd::mapFigurePixel(grid, v, v);
        EXPECT_LE(std::abs(p.first), 1000000 + 200) << v;
        EXPECT_LE(std::abs(p.second), 1000000 + 200) << v;
    }
    // A track that jumps a terametre away is drawn (clipped), not a crash.
    kfd::MapFigureInput in;
    in.grid = &grid;
    in.estimate = {{0.0, {0.0, 0.0, 0.0}}, {1.0, {1e12, 1e12, 0.0}}, {2.0, {1.0, 1.0, 0.0}}};
    EXPECT_EQ(kfd::renderMapFigure(in).getWidth(), 200u);
}

TEST(MapFigure, TheScaleBarGrowsWithCoarseCells) {
    for (const float res : {0.05f, 0.2f, 1.0f}) {
        mrpt::maps::COccupancyGridMap2D grid(-100 * res, 100 * res, -100 * res, 100 * res, res);
        kfd::MapFigureInput in;
        in.grid = &grid;
        const auto img = kfd::renderMapFigure(in);
        // The bar is drawn black at the bottom left, from x = 8: at least 19 px long.
        const int y = static_cast<int>(img.getHeight()) - 12;
        int len = 0;
        while (rgbAt(img, 8 + len, y) == (std::array<std::uint8_t, 3>{0, 0, 0})) ++len;
        EXPECT_GE(len, 19) << res;
        EXPECT_LE(len, 60) << res;
    }
}
