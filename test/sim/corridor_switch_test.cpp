// The corridor switch end to end: kfd-filter's library on simulated logs (kfd::Simulator).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "kfd/io/rawlog_filter.h"
#include "kfd/mrpt/config.h"
#include "kfd/sim/simulator.h"
#include "test_files.h"

namespace {

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_corridor_") {}
};

struct Filtered {
    kfd::RawlogFilterSummary summary;
    std::size_t rows = 0, corridor_rows = 0, corridor_keyframes = 0;
};

Filtered filterSimulated(const TempDir& dir, const std::string& world) {
    kfd::SimulationOptions o;
    o.world = world;
    o.duration_s = 8.0;
    o.output = dir / (world + ".rawlog");
    kfd::Simulator().run(o);
    kfd::RawlogFilterOptions f;
    f.input = o.output;
    f.output = dir / (world + "-out.rawlog");
    f.stats_csv = dir / (world + ".csv");
    f.pipeline = kfd::kfdDefaults();
    Filtered r;
    r.summary = kfd::RawlogFilter().run(f);
    std::ifstream csv(f.stats_csv);
    std::string line, header;
    std::getline(csv, header);
    // The view_keyframe stage's declared columns, in the order it declares them.
    EXPECT_NE(header.find(",view_change,changed_fraction,degeneracy,corridor,"), std::string::npos);
    int corridor_col = 0;  // found by name
    for (std::size_t at = 0; at <= header.find(",corridor,"); ++at)
        corridor_col += header[at] == ',';
    while (std::getline(csv, line)) {
        ++r.rows;
        std::stringstream fields(line);
        std::string field;
        for (int col = 0; col <= corridor_col; ++col) std::getline(fields, field, ',');
        const bool corridor = field == "1";
        r.corridor_rows += corridor;
        r.corridor_keyframes += line.find(",1,corridor,") != std::string::npos;
    }
    return r;
}

}  // namespace

TEST(CorridorSwitch, TheSimulatedCorridorIsDegenerateAndKeyframesFollowOdometry) {
    TempDir dir;
    const Filtered c = filterSimulated(dir, "corridor");
    EXPECT_EQ(c.rows, c.summary.scans_in);
    EXPECT_EQ(c.corridor_rows, c.summary.stageTotal("scans_corridor"));
    EXPECT_EQ(c.corridor_keyframes, c.summary.stageTotal("keyframes_corridor"));
    EXPECT_GT(c.summary.stageTotal("scans_corridor"), c.summary.scans_in / 4)
        << "most of a corridor is degenerate";
    EXPECT_GT(c.summary.stageTotal("keyframes_corridor"), 0u);
}

TEST(CorridorSwitch, TheSimulatedOfficeIsNot) {
    TempDir dir;
    const Filtered o = filterSimulated(dir, "office");
    EXPECT_EQ(o.corridor_rows, o.summary.stageTotal("scans_corridor"));
    EXPECT_LT(o.summary.stageTotal("scans_corridor"), o.summary.scans_in / 20);
}
