// kfd/plot/map_figure.h: trajectories land on the right pixels, the figure spans what it draws
// within its pixel budget, and its layers are exactly what it drew.
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

bool isBlue(const std::array<std::uint8_t, 3>& c) {
    return c[0] == 30 && c[1] == 90 && c[2] == 220;
}

std::vector<std::string> names(const kfd::MapFigure& f) {
    std::vector<std::string> out;
    for (const auto& l : f.layers) out.push_back(l.name);
    return out;
}

// Marks the cells of a wall from (x0, y) to (x1, y) occupied, as a scan would.
void wall(mrpt::maps::COccupancyGridMap2D& g, double x0, double x1, double y) {
    for (double x = x0; x <= x1; x += g.getResolution()) g.setCell(g.x2idx(x), g.y2idx(y), 0.0f);
}

}  // namespace

TEST(MapFigure, EstimateIsDrawnWherePlusYIsUp) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    // A vertical segment on the +y side, x = 2 m, y from 1 to 3 m.
    for (int k = 0; k <= 20; ++k) in.estimate.push_back({double(k), {2.0, 1.0 + 0.1 * k, 0.0}});
    const auto fig = kfd::renderMapFigure(in);
    const auto top = fig.frame.pixel(2.0, 3.0);
    const auto bottom = fig.frame.pixel(2.0, 1.0);
    EXPECT_LT(top.second, bottom.second);                      // larger y is higher in the image
    EXPECT_LT(fig.frame.pixel(1.0, 2.0).first, top.first);     // larger x is further right
    EXPECT_NEAR(bottom.second - top.second, 2.0 / 0.05, 1.0);  // the grid's cell a pixel
    EXPECT_TRUE(isBlue(rgbAt(fig.image, top.first, (top.second + bottom.second) / 2)));
    EXPECT_GE(top.second, fig.frame.top);  // below the legend band
    // The grid is drawn the same way up: walls at x 1..3, y = +4 m and x -3..-1, y = -4 m.
    wall(grid, 1.0, 3.0, 4.0);
    wall(grid, -3.0, -1.0, -4.0);
    const auto walled = kfd::renderMapFigure(in);
    auto grey = [&](double x, double y) {
        const auto p = walled.frame.pixel(x, y);
        return rgbAt(walled.image, p.first, p.second)[0];
    };
    EXPECT_EQ(grey(2.0, 4.0), 0);
    EXPECT_EQ(grey(-2.0, -4.0), 0);
    EXPECT_GT(grey(2.0, -4.0), 0);
    EXPECT_GT(grey(-2.0, 4.0), 0);
}

// The map report's case (issue 23): the grid spans the origin, what is drawn lies 576 m away.
TEST(MapFigure, ContentFarFromTheOriginIsCroppedToWhatIsDrawn) {
    mrpt::maps::COccupancyGridMap2D grid(-10, 610, -10, 10, 0.05f);  // 12 400 x 400 cells
    wall(grid, 576.0, 600.0, 2.0);
    kfd::MapFigureInput in;
    in.grid = &grid;
    for (int k = 0; k <= 48; ++k) in.estimate.push_back({double(k), {576.0 + 0.5 * k, 0.0, 0.0}});
    const auto fig = kfd::renderMapFigure(in);
    const int w = static_cast<int>(fig.image.getWidth()),
              h = static_cast<int>(fig.image.getHeight());
    EXPECT_LE(std::max(w, h), in.max_side_px);
    // 24 m of content and a 1 m margin each side at 5 cm a pixel: the content fills most of it.
    EXPECT_FLOAT_EQ(fig.frame.metres_per_pixel, 0.05);
    EXPECT_LE(fig.frame.width, (24.0 + 2 * in.margin_m) / 0.05 + 3);
    EXPECT_GE(24.0 / 0.05, 0.9 * fig.frame.width);
    EXPECT_LE(fig.frame.height, (2.0 + 2 * in.margin_m) / 0.05 + 5);
    // The wall is drawn black where it is.
    const auto p = fig.frame.pixel(590.0, 2.0);
    EXPECT_EQ(rgbAt(fig.image, p.first, p.second)[0], 0);
    EXPECT_TRUE(isBlue(
        rgbAt(fig.image, fig.frame.pixel(590.0, 0.0).first, fig.frame.pixel(590.0, 0.0).second)));
    // The origin is not in it.
    const auto o = fig.frame.pixel(0.0, 0.0);
    EXPECT_LT(o.first, 0);
}

TEST(MapFigure, AHugeExtentStaysWithinThePixelBudgetAndTheScaleBarStaysRight) {
    mrpt::maps::COccupancyGridMap2D grid(-10, 10, -10, 10, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    for (int k = 0; k <= 100; ++k)  // 100 km by 30 km
        in.estimate.push_back({double(k), {1000.0 * k, 300.0 * k, 0.0}});
    for (const auto& [side, pixels] : {std::pair{3000, 6.0e6}, std::pair{600, 1.0e5}}) {
        in.max_side_px = side;
        in.max_pixels = pixels;
        const auto fig = kfd::renderMapFigure(in);
        const double w = fig.image.getWidth(), h = fig.image.getHeight();
        EXPECT_LE(std::max(w, h), side);
        EXPECT_LE(w * h, pixels);
        EXPECT_GT(fig.frame.metres_per_pixel, 0.05);
        // The scale bar's pixels are its metres at the figure's scale.
        EXPECT_NEAR(fig.scale_bar_px * fig.frame.metres_per_pixel, fig.scale_bar_m,
                    fig.frame.metres_per_pixel);
        EXPECT_GE(fig.scale_bar_px, 19);
        int len = 0;
        while (rgbAt(fig.image, 8 + len, fig.scale_bar_row) ==
               (std::array<std::uint8_t, 3>{0, 0, 0}))
            ++len;
        EXPECT_NEAR(len, fig.scale_bar_px + 1, 1);
        // Both ends of the track are in the image, in blue.
        for (const double s : {0.05, 0.95}) {
            const auto p = fig.frame.pixel(s * 1.0e5, s * 3.0e4);
            ASSERT_GE(p.first, 0);
            ASSERT_LT(p.first, w);
            ASSERT_LT(p.second, h);
            bool blue = false;
            for (int d = -1; d <= 1; ++d)
                for (int e = -1; e <= 1; ++e)
                    blue |= isBlue(rgbAt(fig.image, p.first + d, p.second + e));
            EXPECT_TRUE(blue) << s;
        }
    }
    in.max_side_px = 600;  // a title longer than the budget is cut, never widens the image
    in.title = std::string(1000, 'x');
    EXPECT_LE(kfd::renderMapFigure(in).image.getWidth(), 600u);
    in.max_side_px = 50;  // no room for the legend
    EXPECT_THROW(kfd::renderMapFigure(in), kfd::PlotError);
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
    const auto fig = kfd::renderMapFigure(in);
    // The ground truth (green, drawn wider) shows around the estimate after alignment.
    const auto p = fig.frame.pixel(in.estimate[10].pose.x, in.estimate[10].pose.y);
    bool green = false;
    for (int d = -3; d <= 3; ++d) green |= rgbAt(fig.image, p.first, p.second + d)[1] == 160;
    EXPECT_TRUE(green);
    // Aligned, it does not stretch the figure towards (10, 10).
    EXPECT_LT(fig.frame.width * fig.frame.metres_per_pixel, 6.0);
    EXPECT_THROW(kfd::renderMapFigure(kfd::MapFigureInput{}), kfd::PlotError);
}

TEST(MapFigure, DegenerateScansAreMarkedOrange) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    for (int k = 0; k <= 20; ++k) in.estimate.push_back({double(k), {-2.0 + 0.2 * k, 1.0, 0.0}});
    in.corridor = {15};  // x = 1 m
    const auto fig = kfd::renderMapFigure(in);
    auto orange = [&](double x) {
        const auto p = fig.frame.pixel(x, 1.0);
        const auto c = rgbAt(fig.image, p.first, p.second - 3);  // beside the 3 px blue line
        return c[0] == 240 && c[1] == 130 && c[2] == 0;
    };
    EXPECT_TRUE(orange(1.0));
    EXPECT_FALSE(orange(-1.0));
    in.corridor = {99};  // out of range: ignored
    EXPECT_NO_THROW(kfd::renderMapFigure(in));
}

// The legend and the report's caption come from the same list: what was drawn, nothing else.
TEST(MapFigure, LayersAreExactlyTheOnesDrawn) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    EXPECT_TRUE(kfd::renderMapFigure(in).layers.empty());  // an empty grid, nothing else
    EXPECT_EQ(kfd::mapFigureCaption({}), "map figure: nothing drawn");
    wall(grid, -1.0, 1.0, 3.0);
    for (int k = 0; k <= 20; ++k) in.estimate.push_back({double(k), {-2.0 + 0.2 * k, 1.0, 0.0}});
    in.ground_truth = {{0.0, {0.0, 0.0, 0.0}}};  // one pose: no line to draw
    in.odometry = {{0.0, {5.0, 5.0, 0.0}}, {1.0, {std::nan(""), 5.0, 0.0}}};  // no finite segment
    in.corridor = {99};                                                       // out of range
    EXPECT_EQ(names(kfd::renderMapFigure(in)),
              (std::vector<std::string>{"occupancy map", "estimate"}));
    in.keyframes = {0, 10};
    in.corridor = {5};
    in.ground_truth = in.estimate;
    in.odometry = in.estimate;
    const auto fig = kfd::renderMapFigure(in);
    EXPECT_EQ(names(fig), (std::vector<std::string>{"occupancy map", "estimate", "keyframes",
                                                    "ground truth, aligned to the estimate",
                                                    "odometry from the estimate's start",
                                                    "scans the corridor switch found degenerate"}));
    const std::string caption = kfd::mapFigureCaption(fig.layers);
    for (const char* word : {"estimate (blue)", "ground truth", "green", "odometry", "grey",
                             "degenerate", "orange", "keyframes"})
        EXPECT_NE(caption.find(word), std::string::npos) << word;
}

// kfd's scan track (issue 35) is drawn in purple from the estimate's start, whatever its own
// frame: a track starting at the origin of a laser-only run lands on the estimate.
TEST(MapFigure, TheScanTrackIsDrawnFromTheEstimatesStart) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    for (int k = 0; k <= 20; ++k) in.estimate.push_back({double(k), {-2.0 + 0.2 * k, 1.0, 0.0}});
    for (int k = 0; k <= 20; ++k)  // its own frame, and 0.5 m to the left of the estimate
        in.track.push_back({double(k), {0.2 * k, 0.5, 0.0}});
    in.track.front().pose.y = 0.0;
    in.track[1].pose.y = 0.0;
    const auto fig = kfd::renderMapFigure(in);
    EXPECT_EQ(names(fig),
              (std::vector<std::string>{"estimate", "kfd's scan track from the estimate's start"}));
    auto purple = [&](double x, double y) {
        const auto p = fig.frame.pixel(x, y);
        const auto c = rgbAt(fig.image, p.first, p.second);
        return c[0] == 160 && c[1] == 40 && c[2] == 180;
    };
    EXPECT_TRUE(purple(1.0, 1.5));   // x -2 + 3 m, y 1 + 0.5 m
    EXPECT_FALSE(purple(1.0, 2.5));  // nothing where the track's own frame would put it
    EXPECT_NE(kfd::mapFigureCaption(fig.layers).find("purple"), std::string::npos);
}

TEST(MapFigure, PointsFarAwayOrNotFiniteAreClampedNotCastBeyondAnInt) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureFrame frame;
    frame.width = frame.height = 200;
    for (const double v : {1e12, -1e12, 1e300, std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN()}) {
        const auto p = frame.pixel(v, v);
        EXPECT_LE(std::abs(p.first), 1000000 + 200) << v;
        EXPECT_LE(std::abs(p.second), 1000000 + 200) << v;
    }
    // A track that jumps a terametre away is drawn within the budget, not a crash; one beyond
    // 1e15 m or not finite does not stretch the figure.
    kfd::MapFigureInput in;
    in.grid = &grid;
    in.estimate = {{0.0, {0.0, 0.0, 0.0}}, {1.0, {1e12, 1e12, 0.0}}, {2.0, {1.0, 1.0, 0.0}}};
    const auto fig = kfd::renderMapFigure(in);
    EXPECT_LE(std::max(fig.image.getWidth(), fig.image.getHeight()), 3000u);
    in.estimate = {{0.0, {0.0, 0.0, 0.0}},
                   {1.0, {1e300, std::nan(""), 0.0}},
                   {2.0, {1.0, 1.0, 0.0}},
                   {3.0, {1.0, 2.0, 0.0}}};
    EXPECT_FLOAT_EQ(kfd::renderMapFigure(in).frame.metres_per_pixel, 0.05);
}

TEST(MapFigure, TheScaleBarGrowsWithCoarseCells) {
    for (const float res : {0.05f, 0.2f, 1.0f}) {
        mrpt::maps::COccupancyGridMap2D grid(-100 * res, 100 * res, -100 * res, 100 * res, res);
        kfd::MapFigureInput in;
        in.grid = &grid;
        const auto fig = kfd::renderMapFigure(in);
        // The bar is drawn black in the legend band, from x = 8: at least 19 px long.
        int len = 0;
        while (rgbAt(fig.image, 8 + len, fig.scale_bar_row) ==
               (std::array<std::uint8_t, 3>{0, 0, 0}))
            ++len;
        EXPECT_GE(len, 19) << res;
        EXPECT_LE(len, 60) << res;
        EXPECT_LT(fig.scale_bar_row, fig.frame.top);
    }
}

// Issue 37: where every trajectory coincides (an accurate estimate, odometry that needed no
// correction) each one in the legend still shows in the map, with the keyframes, degenerate
// scans and a lost track; the title is drawn in the band.
TEST(MapFigure, EveryLegendEntryShowsWhereTheTrajectoriesCoincide) {
    mrpt::maps::COccupancyGridMap2D grid(-5, 5, -5, 5, 0.05f);
    kfd::MapFigureInput in;
    in.grid = &grid;
    for (int k = 0; k <= 60; ++k) in.estimate.push_back({double(k), {-3.0 + 0.1 * k, 0.5, 0.0}});
    in.ground_truth = in.odometry = in.track = in.estimate;
    for (std::size_t k = 0; k <= 60; k += 3) in.keyframes.push_back(k);  // dense keyframes
    in.corridor = {10, 11, 12};
    in.lost_tracks = {40};
    in.title = "office.rawlog  mode kfd  dropped 66.7 %  ATE 0.000 m  1 suspected lost track";
    const auto fig = kfd::renderMapFigure(in);
    struct Want {
        const char* name;
        std::array<std::uint8_t, 3> rgb;
    };
    const std::vector<Want> colours = {
        {"estimate", {30, 90, 220}},
        {"keyframes", {10, 20, 90}},
        {"ground truth, aligned to the estimate", {30, 160, 60}},
        {"odometry from the estimate's start", {150, 150, 150}},
        {"kfd's scan track from the estimate's start", {160, 40, 180}},
        {"scans the corridor switch found degenerate", {240, 130, 0}},
        {"suspected lost track begins", {220, 0, 0}}};
    const auto& drawn = fig.layers;  // an empty grid: no occupancy map layer
    ASSERT_EQ(drawn.size(), colours.size());
    const int w = static_cast<int>(fig.image.getWidth());
    for (std::size_t i = 0; i < colours.size(); ++i) {
        EXPECT_EQ(drawn[i].name, colours[i].name);
        std::size_t seen = 0;  // pixels of this colour in the map part (below the band)
        for (int y = fig.frame.top; y < fig.frame.top + fig.frame.height; ++y)
            for (int x = 0; x < w; ++x) seen += rgbAt(fig.image, x, y) == colours[i].rgb;
        EXPECT_GT(seen, 0u) << colours[i].name << " is hidden";
    }
    std::size_t dark = 0;  // the title's text in its row of the band
    for (int y = 8; y < 24; ++y)
        for (int x = 8; x < 8 + 9 * 20; ++x) dark += rgbAt(fig.image, x, y)[0] < 100;
    EXPECT_GT(dark, 50u);
    in.title.clear();
    const auto untitled = kfd::renderMapFigure(in);
    EXPECT_LT(untitled.frame.top, fig.frame.top);  // the title row is gone
}
