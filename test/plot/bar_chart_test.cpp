// kfd/plot/bar_chart.h: bars where the values say, errors on bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <utility>

#include "kfd/plot/bar_chart.h"

namespace {

int columnOfColour(const mrpt::img::CImage& img, int row, mrpt::img::TColor c) {
    for (unsigned x = 0; x < img.getWidth(); ++x) {
        const auto* p = img.ptr<std::uint8_t>(x, row);
        if (p[2] == c.R && p[1] == c.G && p[0] == c.B) return static_cast<int>(x);
    }
    return -1;
}

kfd::BarChart twoByTwo() {
    kfd::BarChart c;
    c.title = "test";
    c.groups = {"a", "b"};
    c.series = {"s1", "s2"};
    c.values = {{1.0, 2.0}, {4.0, 0.5}};
    c.errors = {{0.1, 0.2}, {0.4, 0.05}};
    c.width = 400;
    c.height = 300;
    return c;
}

}  // namespace

TEST(BarChart, TallerValueMeansTallerBar) {
    const auto img = twoByTwo().render();
    ASSERT_EQ(img.getWidth(), 400u);
    // Just above the x axis every bar shows its series colour; higher up only the tall ones.
    const int bottom = 300 - 90 - 2;
    EXPECT_GE(columnOfColour(img, bottom, kfd::BarChart::seriesColour(0)), 0);
    EXPECT_GE(columnOfColour(img, bottom, kfd::BarChart::seriesColour(1)), 0);
    // Value 4 (group b, s1) spans most of the height; value 2 (group a, s2) about half.
    const int high = 90;  // axis 0..5: value 4 reaches row 74, value 2 only row 142
    EXPECT_GE(columnOfColour(img, high, kfd::BarChart::seriesColour(0)), 200);  // in group b
    EXPECT_EQ(columnOfColour(img, high, kfd::BarChart::seriesColour(1)), -1);
}

TEST(BarChart, BadShapesAndLogOfZeroAreErrors) {
    auto c = twoByTwo();
    c.values[1].pop_back();
    EXPECT_THROW(c.render(), kfd::PlotError);
    c = twoByTwo();
    c.log_y = true;
    c.values[0][0] = 0.0;
    EXPECT_THROW(c.render(), kfd::PlotError);
    c.values[0][0] = 0.01;
    EXPECT_NO_THROW(c.render());
}

TEST(BarChart, TheLegendWrapsWithinTheImageAndTheSizeHasABudget) {
    auto c = twoByTwo();
    c.series = {"a long series name one", "a long series name two", "a long series name three"};
    c.values = {{1.0, 2.0, 3.0}, {4.0, 0.5, 1.5}};
    c.errors.clear();
    const auto img = c.render();
    // Every series' swatch is in the legend rows under the axis (rows 240 on), inside the image.
    for (std::size_t s = 0; s < c.series.size(); ++s) {
        bool found = false;
        for (int row = 300 - 90 + 30; row < 300 && !found; ++row)
            found = columnOfColour(img, row, kfd::BarChart::seriesColour(s)) >= 0;
        EXPECT_TRUE(found) << s;
    }
    for (const auto& [w, h] : {std::pair{100, 300}, std::pair{20000, 500}, std::pair{9000, 9000}}) {
        c.width = w, c.height = h;
        EXPECT_THROW(c.render(), kfd::PlotError) << w << " x " << h;
    }
}

TEST(BarChart, ReadsCsvInFirstSeenOrder) {
    const auto f = (std::filesystem::temp_directory_path() / "kfd_chart.csv").string();
    std::ofstream(f) << "dataset,mode,value,error\nintel,kfd,4.6,7.9\nintel,none,4.1,6.1\n"
                        "aces,none,0.17,0.47\n";
    const auto c = kfd::readBarChartCsv(f);
    EXPECT_EQ(c.groups, (std::vector<std::string>{"intel", "aces"}));
    EXPECT_EQ(c.series, (std::vector<std::string>{"kfd", "none"}));
    EXPECT_DOUBLE_EQ(c.values[0][0], 4.6);
    EXPECT_DOUBLE_EQ(c.errors[1][1], 0.47);
    EXPECT_TRUE(std::isnan(c.values[1][0]));  // aces/kfd missing: no bar
    std::ofstream(f) << "h\nx,y,notanumber\n";
    EXPECT_THROW(kfd::readBarChartCsv(f), kfd::PlotError);
    std::filesystem::remove(f);
}
