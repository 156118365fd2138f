// A stage's declared outputs: its per-scan columns and its counters, bound to the pipeline's
// listed stages (a stage listed twice, a stage that did not run, kept-only counters).
#include "kfd/pipeline/stage_outputs.h"

#include <algorithm>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/pipeline/pipeline.h"
#include "kfd/pipeline/stage_registry.h"
#include "kfd/stages/core_stages.h"
#include "test_scans.h"

namespace kfd {
namespace {

// A hand-made stage that declares one column and two counters in this one place: what a new
// diagnostic costs (issue 34). It counts its scans and drops every other one.
struct Tally {
    std::size_t seen = 0;
};
class TallyStage : public Stage {
  public:
    static constexpr const char* kName = "tally";
    static constexpr const char* kHelp = "test: counts scans, drops every other one";
    struct Params {};
    static std::vector<StageKey> keys() { return {}; }
    static std::vector<StageColumn> columns() {
        return {diagnosticColumn<Tally>("seen", "scans seen so far", "%zu",
                                        [](const Tally& t) { return t.seen; })};
    }
    static std::vector<StageCounter> counters() {
        return {diagnosticCounter<Tally>("tally_all", "scans it ran on", false,
                                         [](const Tally&) { return 1; }),
                diagnosticCounter<Tally>("tally_kept", "kept scans it ran on", true,
                                         [](const Tally&) { return 1; })};
    }
    explicit TallyStage(const Params&) {}
    const char* name() const override { return kName; }
    bool process(Scan&, StageReport& report, const ScanReport&) override {
        report.setDiagnostics(Tally{++seen_});
        return seen_ % 2 == 1;
    }

  private:
    std::size_t seen_ = 0;
};

StageRegistry registryWithTally() {
    StageRegistry r = makeStageRegistry({registerCoreStages});
    r.add<TallyStage>();
    return r;
}

TEST(StageOutputs, ColumnsAreTheListedStagesDeclarationsInPipelineOrder) {
    const StageRegistry r = registryWithTally();
    const StageOutputs paper({"distance", "keyframe", "denoise"}, r);
    EXPECT_EQ(paper.columns(),
              (std::vector<std::string>{"removed_range", "p_common", "p_threshold", "references",
                                        "clusters", "noise_clusters"}));
    const StageOutputs tally({"tally", "distance"}, r);
    EXPECT_EQ(tally.columns(), (std::vector<std::string>{"seen", "removed_range"}));
}

TEST(StageOutputs, AStageListedTwiceGetsItsColumnsAndCountersAgainUnderItsSecondName) {
    const StageRegistry r = registryWithTally();
    const StageOutputs twice({"tally", "tally"}, r);
    EXPECT_EQ(twice.columns(), (std::vector<std::string>{"seen", "tally_2.seen"}));
    ASSERT_EQ(twice.zeroTotals().size(), 4u);
    EXPECT_EQ(twice.zeroTotals()[2].name, "tally_2.tally_all");
    EXPECT_EQ(twice.zeroTotals()[2].stage, "tally_2");
}

TEST(StageOutputs, AColumnNameTwoStagesDeclareIsPrefixedInTheSecond) {
    const StageOutputs both({"keyframe", "view_keyframe"}, coreStageRegistry());
    const auto& c = both.columns();
    EXPECT_EQ(std::count(c.begin(), c.end(), "references"), 1);
    EXPECT_EQ(std::count(c.begin(), c.end(), "view_keyframe.references"), 1);
}

TEST(StageOutputs, CellsComeFromEachStagesOwnReportAndAbsentWhenItDidNotRun) {
    const StageRegistry r = registryWithTally();
    Pipeline::Params p;
    p.stages = {"tally", "distance"};  // distance runs only on the scans tally keeps
    Pipeline pipeline(p, r);
    const StageOutputs out(p.stages, r);
    std::vector<StageTotal> totals = out.zeroTotals();
    std::vector<std::string> rows;
    std::vector<ScanReport> reports;
    for (int i = 0; i < 4; ++i) {
        Scan s = test::noisyWall();  // beam 60 out of range, beam 61 NaN
        reports.push_back(pipeline.process(s));
        rows.push_back(out.cells(reports.back()));
        out.count(reports.back(), totals);
    }
    EXPECT_EQ(rows, (std::vector<std::string>{",1,2", ",2,0", ",3,2", ",4,0"}));
    EXPECT_EQ(out.cell(reports[2], "removed_range"), "2");
    EXPECT_EQ(out.cell(reports[2], "seen"), "3");
    EXPECT_EQ(out.cell(reports[2], "no_such_column"), "");
    EXPECT_EQ(out.cells(ScanReport{}), ",0,0");  // a skipped scan: no stage ran
    EXPECT_EQ(totalOf(totals, "tally_all"), 4.0);
    EXPECT_EQ(totalOf(totals, "tally_kept"), 2.0);  // kept scans only
    EXPECT_EQ(totalOf(totals, "points_removed_range"), 4.0);
    EXPECT_EQ(totalOf(totals, "not_declared"), 0.0);
    EXPECT_EQ(
        stageCounterLines(totals),
        (std::vector<std::string>{"tally: 4 scans it ran on; 2 kept scans it ran on",
                                  "distance: 4 points out of range removed from kept scans"}));
}

TEST(StageOutputs, EachInstanceOfAStageListedTwiceHasItsOwnCells) {
    const StageRegistry r = registryWithTally();
    Pipeline::Params p;
    p.stages = {"tally", "tally"};  // the second runs only on the scans the first keeps
    Pipeline pipeline(p, r);
    const StageOutputs out(p.stages, r);
    std::vector<StageTotal> totals = out.zeroTotals();
    std::vector<std::string> rows;
    std::vector<ScanReport> reports;
    for (int i = 0; i < 4; ++i) {
        Scan s = test::noisyWall();
        reports.push_back(pipeline.process(s));
        rows.push_back(out.cells(reports.back()));
        out.count(reports.back(), totals);
    }
    // The first sees 1, 2, 3, 4 and keeps 1 and 3; the second sees those two, keeps the first.
    EXPECT_EQ(rows, (std::vector<std::string>{",1,1", ",2,0", ",3,2", ",4,0"}));
    EXPECT_EQ(out.cell(reports[2], "tally_2.seen"), "2");
    EXPECT_EQ(totalOf(totals, "tally_all"), 4.0);
    EXPECT_EQ(totalOf(totals, "tally_2.tally_all"), 2.0);
    EXPECT_EQ(totalOf(totals, "tally_2.tally_kept"), 1.0);
}

TEST(StageOutputs, AnUnknownStageIsAnErrorNamingIt) {
    try {
        StageOutputs({"distance", "nosuch"}, coreStageRegistry());
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("'nosuch'"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace kfd
