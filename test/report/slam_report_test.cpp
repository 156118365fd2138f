// kfd/report/slam_report.h: report.md carries every number the console prints, with units, and
// a figure caption naming exactly the layers drawn.
#include <gtest/gtest.h>

#include <regex>
#include <sstream>

#include "kfd/report/slam_report.h"

namespace {

// A summary with every optional part present and numbers that appear nowhere else.
kfd::IcpSlamSummary fullSummary() {
    kfd::IcpSlamSummary s;
    s.rawlog = "/logs/run.rawlog";
    s.output_dir = "/tmp/out";
    s.scans_in = 1988, s.scans_kept = 1713, s.dropped_pct = 13.8;
    s.points_in = 717668, s.points_removed = 4321;
    s.prefilter_us_per_scan = 41.7, s.icp_ms_per_scan = 3.219, s.cpu_s_total = 17.43;
    s.wall_s_total = 18.61;
    s.icp_runs = 611, s.icp_rejected = 7, s.icp_goodness_median = 0.87;
    s.rematches = 5, s.gap_checks_failed = 3, s.rematches_recovered = 2, s.scans_rematched = 29;
    s.lost_track_stamps = {1234.567, 1300.25};
    s.ate_rmse = 0.04567;
    kfd::RelationsError all, local, along;
    all.used = 1172, all.unmatched = 4, all.trans_mean = 0.2345, all.trans_std = 0.3456;
    all.rot_mean_deg = 1.234, all.rot_std_deg = 2.345;
    local.used = 1010, local.unmatched = 3, local.trans_mean = 0.0789, local.trans_std = 0.0912;
    local.rot_mean_deg = 0.456, local.rot_std_deg = 0.567;
    along.used = 162, along.unmatched = 1, along.trans_mean = 1.2121, along.trans_std = 0.9393;
    along.rot_mean_deg = 6.789, along.rot_std_deg = 5.678;
    s.relations = all, s.relations_local = local, s.relations_long = along;
    s.relations_local_count = 1013, s.relations_long_count = 163;
    s.split_seconds = 12.5;
    s.target_drop_pct = 13.75;
    return s;
}

const std::vector<kfd::MapFigureLayer> kLaserOnlyLayers = {
    {"occupancy map", "white free, black occupied"}, {"estimate", "blue"}};

}  // namespace

TEST(SlamReport, ReportCarriesEveryNumberTheConsolePrints) {
    const auto s = fullSummary();
    const std::string console = kfd::summaryText(s), report = kfd::reportMarkdown(s, {});
    std::istringstream lines(console);
    std::string line;
    const std::regex number(R"([0-9]+(\.[0-9]+)?)");
    std::size_t checked = 0;
    while (std::getline(lines, line)) {
        if (line.find("input") != std::string::npos || line.find("output") != std::string::npos)
            continue;  // paths
        for (std::sregex_iterator it(line.begin(), line.end(), number), end; it != end; ++it) {
            EXPECT_NE(report.find(it->str()), std::string::npos) << it->str() << " of: " << line;
            ++checked;
        }
    }
    EXPECT_GT(checked, 30u);
}

TEST(SlamReport, LocalAndLongRelationsWithTheirCountsAndUnits) {
    auto s = fullSummary();
    const std::string report = kfd::reportMarkdown(s, {});
    EXPECT_NE(report.find("- local (<= 12.5 s apart, 1013 relations): 1010 used, 3 unmatched: "
                          "0.0789 +- 0.0912 m, 0.456 +- 0.567 deg"),
              std::string::npos)
        << report;
    EXPECT_NE(report.find("- long (> 12.5 s apart, 163 relations): 162 used, 1 unmatched: "
                          "1.2121 +- 0.9393 m, 6.789 +- 5.678 deg"),
              std::string::npos)
        << report;
    EXPECT_NE(report.find("wall 18.61 s"), std::string::npos);
    EXPECT_NE(report.find("ATE RMSE after SE(2) alignment: 0.0457 m"), std::string::npos);
    // A subset without a match, an empty one.
    s.relations_long.reset();
    s.relations_local.reset();
    s.relations_local_count = 0;
    const std::string none = kfd::reportMarkdown(s, {});
    EXPECT_NE(none.find("- long (> 12.5 s apart, 163 relations): none matched a pose"),
              std::string::npos)
        << none;
    EXPECT_NE(none.find("- local (<= 12.5 s apart, 0 relations): none"), std::string::npos);
    // Without relations, no such lines.
    s.relations.reset();
    EXPECT_EQ(kfd::reportMarkdown(s, {}).find("relations"), std::string::npos);
}

TEST(SlamReport, FigureCaptionNamesOnlyTheLayersDrawn) {
    const std::string laser_only = kfd::reportMarkdown(fullSummary(), kLaserOnlyLayers);
    EXPECT_NE(laser_only.find("![map figure: occupancy map (white free, black occupied), "
                              "estimate (blue)](map_figure.png)"),
              std::string::npos)
        << laser_only;
    const auto from = laser_only.find("!["), to = laser_only.find('\n', from);
    const std::string figure = laser_only.substr(from, to - from);  // alt text and caption
    const std::string caption = laser_only.substr(to);
    for (const char* absent : {"ground truth", "odometry", "keyframes", "degenerate"}) {
        EXPECT_EQ(figure.find(absent), std::string::npos) << absent;
        EXPECT_EQ(caption.find(absent), std::string::npos) << absent;
    }
    auto layers = kLaserOnlyLayers;
    layers.push_back({"ground truth, aligned to the estimate", "green"});
    layers.push_back({"odometry from the estimate's start", "grey"});
    const std::string full = kfd::reportMarkdown(fullSummary(), layers);
    EXPECT_NE(full.find("ground truth, aligned to the estimate (green)"), std::string::npos);
    EXPECT_NE(full.find("odometry from the estimate's start (grey)"), std::string::npos);
}
