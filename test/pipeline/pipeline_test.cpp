#include "kfd/pipeline/pipeline.h"
#include "kfd/stages/core_stages.h"

#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

std::vector<std::string> stageNames(const Pipeline& p) {
    std::vector<std::string> names;
    for (const auto& s : p.stages()) names.emplace_back(s->name());
    return names;
}

// The paper's denoiser (Algorithm 2) after kfd's keyframe stage: the expectations below
// follow Algorithm 2.
Pipeline::Params paper() {
    Pipeline::Params p;
    p.stages = {"distance", "view_keyframe", "denoise"};
    return p;
}

Pipeline::Params withStages(std::vector<std::string> stages) {
    Pipeline::Params p = paper();
    p.stages = std::move(stages);
    return p;
}

// test::noisyWall: the distance stage removes beams 60 (45 m) and 61 (NaN), the denoise stage
// the outliers at beams 50, 100 and 130.
using test::noisyWall;

/// Records what the chain passes through it.
class RecordingStage : public Stage {
  public:
    RecordingStage(const char* name, bool keep, int* calls, int* resets = nullptr)
        : name_(name), keep_(keep), calls_(calls), resets_(resets) {}
    const char* name() const override { return name_; }
    bool process(Scan& scan, StageReport&, const ScanReport& chain) override {
        ++*calls_;
        seen_valid = scan.countValid();
        seen_denoised = chain.find<DenoiseResult>() != nullptr;
        return keep_;
    }
    void observeDropped(const Scan& scan, const ScanReport&) override {
        ++observed;
        observed_valid = scan.countValid();
    }
    void reset() override {
        if (resets_) ++*resets_;
    }
    std::size_t seen_valid = 0;
    bool seen_denoised = false;
    int observed = 0;                // dropped scans shown to it
    std::size_t observed_valid = 0;  // valid beams of the last one

  private:
    const char* name_;
    bool keep_;
    int* calls_;
    int* resets_;
};

// The default pipeline names kfd's stages; the paper's are stages of their own.
TEST(Pipeline, DefaultStageOrderNamesKfdsStages) {
    const Pipeline p;
    const std::vector<std::string> kfds{"distance", "view_keyframe", "evidence_denoise"};
    EXPECT_EQ(stageNames(p), kfds);
    EXPECT_EQ(p.params().stages, kfds);
    const Pipeline paper(withStages({"distance", "keyframe", "denoise"}));
    EXPECT_NE(paper.find<kfd::KeyframeStage>(), nullptr);
    EXPECT_NE(paper.find<kfd::DenoiseStage>(), nullptr);
    EXPECT_EQ(paper.find<kfd::ViewKeyframeStage>(), nullptr);
    EXPECT_EQ(paper.find<kfd::EvidenceDenoiseStage>(), nullptr);
}

TEST(Pipeline, CustomStageOrder) {
    const Pipeline p(withStages({"denoise", "distance"}));
    EXPECT_EQ(stageNames(p), (std::vector<std::string>{"denoise", "distance"}));
}

TEST(Pipeline, UnknownStageThrows) {
    EXPECT_THROW(Pipeline(withStages({"distance", "median"})), kfd::ParameterError);
    EXPECT_THROW(Pipeline(withStages({"Distance"})), kfd::ParameterError);
    EXPECT_THROW(Pipeline(withStages({""})), kfd::ParameterError);
}

TEST(Pipeline, AStageListedTwiceRunsTwiceWithTheParametersOfEachInstance) {
    EXPECT_EQ(instanceNames({"denoise", "distance", "denoise", "denoise"}),
              (std::vector<std::string>{"denoise", "distance", "denoise_2", "denoise_3"}));
    Pipeline::Params params = withStages({"distance", "keyframe", "distance"});
    const StageInfo& distance = *coreStageRegistry().find("distance");
    static_cast<DistanceFilter::Params*>(params.at(distance, "distance_2").data())->max_range =
        2.0;  // the second instance narrows the range; the first keeps the scan's own
    Pipeline p(params);
    EXPECT_EQ(stageNames(p), (std::vector<std::string>{"distance", "keyframe", "distance"}));
    Scan s = test::flatWall(181, kPi, 3.0);  // every return beyond 2 m but within the scan's own
    const ScanReport r = p.process(s);
    ASSERT_EQ(r.stage_count, 3u);
    EXPECT_EQ(r.stage_reports[0].points_removed, 0u);
    EXPECT_EQ(r.stage_reports[2].points_removed, 181u);
}

TEST(Pipeline, InvalidStageParamsThrow) {
    auto p = withStages({"distance", "keyframe", "denoise"});
    p.get<kfd::KeyframeStage>().bins = 1;
    EXPECT_THROW(Pipeline{p}, kfd::ParameterError);
    p = withStages({"distance"});
    p.get<kfd::DistanceStage>().min_range = 5.0;
    p.get<kfd::DistanceStage>().max_range = 1.0;
    EXPECT_THROW(Pipeline{p}, kfd::ParameterError);
    p = withStages({"denoise"});
    p.get<kfd::DenoiseStage>().m_threshold = 0;
    EXPECT_THROW(Pipeline{p}, kfd::ParameterError);
}

TEST(Pipeline, FirstScanRunsEveryStage) {
    Pipeline p;
    Scan scan = noisyWall();
    const auto r = p.process(scan);
    EXPECT_TRUE(r.keep);
    EXPECT_TRUE(r.dropped_by.empty());
    EXPECT_NE(r.find<kfd::KeyframeDecision>(), nullptr);
    EXPECT_EQ(r.findOrDefault<kfd::KeyframeDecision>().reason, KeyframeReason::First);
    EXPECT_NE(r.find<kfd::DenoiseResult>(), nullptr);
    EXPECT_EQ(r.points_in, 121u);
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().valid_in, 121u);
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().removed_out_of_range, 1u);
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().removed_non_finite, 1u);
    EXPECT_EQ(r.findOrDefault<kfd::DenoiseResult>().points_in, 119u);
    EXPECT_EQ(r.findOrDefault<kfd::DenoiseResult>().points_removed, 3u);
    EXPECT_EQ(r.points_out, 116u);
    EXPECT_EQ(scan.countValid(), 116u);
    for (const std::size_t i : {50u, 60u, 61u, 100u, 130u}) EXPECT_EQ(scan.valid[i], 0u) << i;
}

TEST(Pipeline, DroppedScanStopsLaterStages) {
    Pipeline p;
    Scan first = noisyWall();
    p.process(first);
    Scan second = noisyWall();  // the same view again
    second.timestamp = 100.1;
    const auto r = p.process(second);
    EXPECT_FALSE(r.keep);
    EXPECT_EQ(r.dropped_by, "view_keyframe");
    EXPECT_NE(r.find<kfd::KeyframeDecision>(), nullptr);
    EXPECT_EQ(r.findOrDefault<kfd::KeyframeDecision>().reason, KeyframeReason::Covered);
    EXPECT_EQ(r.find<kfd::DenoiseResult>(), nullptr);
    EXPECT_EQ(r.findOrDefault<kfd::DenoiseResult>().points_removed, 0u);
    // The distance stage ran before the drop; the denoise stage did not run.
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().removed_out_of_range, 1u);
    EXPECT_EQ(second.valid[60], 0u);
    for (const std::size_t i : {50u, 100u, 130u}) EXPECT_EQ(second.valid[i], 1u) << i;
    EXPECT_EQ(r.points_out, 119u);
}

TEST(Pipeline, NoKeyframeStageKeepsEveryScan) {
    Pipeline p(withStages({"distance", "denoise"}));
    for (int k = 0; k < 3; ++k) {
        Scan scan = noisyWall();
        const auto r = p.process(scan);
        EXPECT_TRUE(r.keep);
        EXPECT_EQ(r.find<kfd::KeyframeDecision>(), nullptr);
        EXPECT_NE(r.find<kfd::DenoiseResult>(), nullptr);
        EXPECT_EQ(r.points_out, 116u);
    }
}

TEST(Pipeline, StagesRunInTheListedOrder) {
    // Denoise before the distance filter: the out-of-range (45 m) and NaN beams are still
    // flagged valid when the clustering runs, and the distance filter then sees the denoised
    // scan.
    Pipeline p(withStages({"denoise", "distance"}));
    Scan scan = noisyWall();
    const auto r = p.process(scan);
    EXPECT_EQ(r.findOrDefault<kfd::DenoiseResult>().points_in, 121u);
    EXPECT_GE(r.findOrDefault<kfd::DenoiseResult>().points_removed, 1u);
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().valid_in,
              121u - r.findOrDefault<kfd::DenoiseResult>().points_removed);
}

TEST(Pipeline, CustomStageViaAdd) {
    Pipeline p;
    int calls = 0;
    auto stage = std::make_unique<RecordingStage>("recorder", true, &calls);
    RecordingStage* rec = stage.get();
    p.add(std::move(stage));
    EXPECT_EQ(stageNames(p), (std::vector<std::string>{"distance", "view_keyframe",
                                                       "evidence_denoise", "recorder"}));
    Scan scan = noisyWall();
    EXPECT_TRUE(p.process(scan).keep);
    EXPECT_EQ(calls, 1);
    EXPECT_EQ(rec->seen_valid, 116u);  // after the built-in stages
    EXPECT_TRUE(rec->seen_denoised);
    Scan again = noisyWall();
    EXPECT_FALSE(p.process(again).keep);  // dropped by the keyframe stage first
    EXPECT_EQ(calls, 1);
}

TEST(Pipeline, CustomStageCanDropScans) {
    Pipeline p(withStages({"distance"}));
    int first_calls = 0, second_calls = 0;
    p.add(std::make_unique<RecordingStage>("gate", false, &first_calls));
    p.add(std::make_unique<RecordingStage>("after", true, &second_calls));
    Scan scan = noisyWall();
    const auto r = p.process(scan);
    EXPECT_FALSE(r.keep);
    EXPECT_EQ(r.dropped_by, "gate");
    EXPECT_EQ(first_calls, 1);
    EXPECT_EQ(second_calls, 0);
}

TEST(Pipeline, StagesAfterTheDropSeeTheDroppedScanAndStagesBeforeItDoNot) {
    Pipeline p(withStages({"distance"}));
    int calls[3] = {0, 0, 0};
    auto before = std::make_unique<RecordingStage>("before", true, &calls[0]);
    auto gate = std::make_unique<RecordingStage>("gate", false, &calls[1]);
    auto after = std::make_unique<RecordingStage>("after", true, &calls[2]);
    RecordingStage *b = before.get(), *g = gate.get(), *a = after.get();
    p.add(std::move(before));
    p.add(std::move(gate));
    p.add(std::move(after));
    Scan scan = noisyWall();
    EXPECT_FALSE(p.process(scan).keep);
    EXPECT_EQ(b->observed, 0);  // it processed the scan
    EXPECT_EQ(g->observed, 0);  // it dropped it
    EXPECT_EQ(a->observed, 1);
    EXPECT_EQ(calls[2], 0);
    EXPECT_EQ(a->observed_valid, g->seen_valid);  // as the gate saw it: after the distance stage
    EXPECT_LT(a->observed_valid, noisyWall().countValid());
}

TEST(Pipeline, AddRejectsNull) {
    Pipeline p;
    EXPECT_THROW(p.add(nullptr), kfd::Error);
    EXPECT_EQ(p.stages().size(), 3u);
}

TEST(Pipeline, EmptyPipelineKeepsEverything) {
    Pipeline p(withStages({}));
    Scan scan = noisyWall();
    const Scan before = scan;
    const auto r = p.process(scan);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.find<kfd::KeyframeDecision>(), nullptr);
    EXPECT_EQ(r.find<kfd::DenoiseResult>(), nullptr);
    EXPECT_EQ(scan.valid, before.valid);
    EXPECT_EQ(r.points_in, r.points_out);
    EXPECT_EQ(p.lastClusters(), nullptr);
}

TEST(Pipeline, ResetMakesTheNextScanAKeyframe) {
    Pipeline p;
    int calls = 0, resets = 0;
    p.add(std::make_unique<RecordingStage>("recorder", true, &calls, &resets));
    Scan a = noisyWall();
    p.process(a);
    Scan b = noisyWall();
    ASSERT_FALSE(p.process(b).keep);
    p.reset();
    EXPECT_EQ(resets, 1);  // custom stages are reset too
    Scan c = noisyWall();
    const auto r = p.process(c);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.findOrDefault<kfd::KeyframeDecision>().reason, KeyframeReason::First);
    EXPECT_NE(r.find<kfd::DenoiseResult>(), nullptr);
}

TEST(Pipeline, PreservesGeometryAndOnlyClearsValidFlags) {
    Pipeline p;
    Scan scan = noisyWall();
    scan.odometry = Pose2D{1.0, 2.0, 0.5};
    scan.valid[0] = 1;  // a few stray valid beams at range 0 (out of range)
    scan.valid[180] = 1;
    const Scan before = scan;
    p.process(scan);
    ASSERT_EQ(scan.size(), before.size());
    ASSERT_EQ(scan.valid.size(), before.valid.size());
    EXPECT_EQ(scan.geometry, before.geometry);
    EXPECT_EQ(
        std::memcmp(scan.range.data(), before.range.data(), scan.range.size() * sizeof(float)),
        0);  // bit for bit, NaN included
    EXPECT_EQ(scan.timestamp, before.timestamp);
    ASSERT_TRUE(scan.odometry.has_value());
    EXPECT_EQ(scan.odometry->x, 1.0);
    EXPECT_EQ(scan.odometry->phi, 0.5);
    for (std::size_t i = 0; i < scan.size(); ++i)
        EXPECT_LE(scan.valid[i], before.valid[i]) << "beam " << i << " became valid";
    EXPECT_LT(scan.countValid(), before.countValid());
}

TEST(Pipeline, RejectsScanWithMismatchedSizes) {
    Pipeline p;
    Scan scan = noisyWall();
    scan.valid.pop_back();
    EXPECT_THROW(p.process(scan), kfd::Error);
}

TEST(Pipeline, LastClustersComeFromTheDenoiseStage) {
    EXPECT_EQ(Pipeline(withStages({"distance", "keyframe"})).lastClusters(), nullptr);
    Pipeline p(paper());
    Scan scan = noisyWall();
    p.process(scan);
    const Clusters* c = p.lastClusters();
    ASSERT_NE(c, nullptr);
    ASSERT_EQ(c->label.size(), scan.size());
    EXPECT_EQ(c->count(), 4u);  // the wall and three outliers
    EXPECT_EQ(c->label[60], -1);
    EXPECT_GE(c->label[100], 0);
    EXPECT_TRUE(c->noise[static_cast<std::size_t>(c->label[100])]);
}

TEST(Pipeline, StageParamsArePassedOn) {
    auto params = withStages({"distance", "range_aware_denoise"});
    params.get<kfd::DistanceStage>().max_range = 5.0;  // the wall beyond 5 m goes
    Pipeline p(params);
    Scan scan = noisyWall();
    const auto r = p.process(scan);
    EXPECT_EQ(r.findOrDefault<kfd::DenoiseResult>().variant, DenoiseVariant::RangeAware);
    EXPECT_GT(r.findOrDefault<kfd::DistanceFilter::Result>().removed_out_of_range, 1u);
    for (std::size_t i = 0; i < scan.size(); ++i) {
        if (scan.valid[i]) {
            EXPECT_LE(scan.range[i], 5.0f) << i;
        }
    }
}

}  // namespace
}  // namespace kfd

namespace kfd {
namespace {

// One scan of latency (the denoise key next_scan, issue 25): a robot driving towards a wall
// at 10 cm a scan, odometry along; every fifth scan has a 5-beam burst in front of the wall.
std::vector<Scan> approach(std::size_t count) {
    std::vector<Scan> scans;
    for (std::size_t k = 0; k < count; ++k) {
        const double x = 0.1 * static_cast<double>(k);
        Scan s = test::flatWall(361, test::deg2rad(150.0), 6.0 - x);
        s.odometry = Pose2D{x, 0.0, 0.0};
        s.timestamp = 100.0 + 0.1 * static_cast<double>(k);
        if (k % 5 == 2) test::setRange(s, 178, 182, 6.0 - x - 0.5);
        scans.push_back(std::move(s));
    }
    return scans;
}

Pipeline::Params nextScan(bool on) {
    Pipeline::Params p;
    p.get<EvidenceDenoiseStage>().next_scan = on;
    return p;
}

struct Output {
    double stamp;
    bool keep;
    std::vector<std::uint8_t> valid;
};

// Runs the scans through; the outputs in the order the pipeline finishes them.
std::vector<Output> run(Pipeline& p, std::vector<Scan> scans, std::size_t* pending = nullptr) {
    std::vector<Output> out;
    ScanReport done;
    for (Scan& s : scans) {
        const ScanReport r = p.process(s);
        if (const Scan* f = p.finished(done)) {
            EXPECT_FALSE(done.pending);
            out.push_back({f->timestamp, done.keep, f->valid});
        }
        if (r.pending) {
            EXPECT_TRUE(r.keep);
            EXPECT_TRUE(p.holding());
            if (pending) ++*pending;
        } else {
            out.push_back({s.timestamp, r.keep, s.valid});
        }
    }
    if (p.finish()) {
        const Scan* f = p.finished(done);
        EXPECT_NE(f, nullptr);
        if (f) out.push_back({f->timestamp, done.keep, f->valid});
    }
    EXPECT_FALSE(p.holding());
    return out;
}

TEST(PipelineNextScan, AKeyframeIsHeldUntilTheNextScanAndFinishedByIt) {
    Pipeline p(nextScan(true));
    auto scans = approach(2);
    const ScanReport first = p.process(scans[0]);
    EXPECT_TRUE(first.pending);
    EXPECT_TRUE(first.keep);
    EXPECT_EQ(first.find<DenoiseResult>(), nullptr);  // the denoise stage has not run
    ScanReport done;
    EXPECT_EQ(p.finished(done), nullptr);
    p.process(scans[1]);
    const Scan* f = p.finished(done);
    ASSERT_NE(f, nullptr);
    EXPECT_EQ(f->timestamp, scans[0].timestamp);
    EXPECT_FALSE(done.pending);
    ASSERT_NE(done.find<DenoiseResult>(), nullptr);
    EXPECT_TRUE(done.find<DenoiseResult>()->next);  // the next scan was used
    EXPECT_EQ(done.stage_count, 3u);
}

TEST(PipelineNextScan, TheLastKeyframeIsFinishedWithoutANextScan) {
    Pipeline p(nextScan(true));
    Scan only = approach(1)[0];
    EXPECT_TRUE(p.process(only).pending);
    ScanReport done;
    EXPECT_TRUE(p.finish());
    const Scan* f = p.finished(done);
    ASSERT_NE(f, nullptr);
    EXPECT_TRUE(done.keep);
    ASSERT_NE(done.find<DenoiseResult>(), nullptr);
    EXPECT_FALSE(done.find<DenoiseResult>()->next);
    EXPECT_FALSE(p.finish());  // nothing held any more
    // Exactly what the option off gives for a lone scan.
    Pipeline off(nextScan(false));
    Scan same = approach(1)[0];
    off.process(same);
    EXPECT_EQ(f->valid, same.valid);
}

TEST(PipelineNextScan, ResetFinishesTheHeldKeyframeFirst) {
    Pipeline p(nextScan(true));
    Scan only = approach(1)[0];
    EXPECT_TRUE(p.process(only).pending);
    p.reset();
    ScanReport done;
    EXPECT_NE(p.finished(done), nullptr);
    EXPECT_FALSE(p.holding());
}

TEST(PipelineNextScan, OutputsKeepTheInputOrderAndCountsOnlyRemovalsDiffer) {
    Pipeline on(nextScan(true)), off(nextScan(false));
    std::size_t pending = 0;
    const auto a = run(on, approach(30), &pending);
    const auto b = run(off, approach(30));
    EXPECT_GT(pending, 1u);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].stamp, b[i].stamp) << i;
        EXPECT_EQ(a[i].keep, b[i].keep) << i;
        ASSERT_EQ(a[i].valid.size(), b[i].valid.size());
    }
}

TEST(PipelineNextScan, WithoutTheOptionNothingIsHeld) {
    Pipeline p(nextScan(false));
    for (Scan& s : approach(10)) {
        EXPECT_FALSE(p.process(s).pending);
        ScanReport done;
        EXPECT_EQ(p.finished(done), nullptr);
    }
    EXPECT_FALSE(p.finish());
}

// A stage that holds each scan for the next (Stage::defers): it records what finish() got.
class HoldingStage : public Stage {
  public:
    const char* name() const override { return "hold"; }
    bool process(Scan&, StageReport&, const ScanReport&) override {
        ADD_FAILURE() << "process() called on a holding stage";
        return true;
    }
    bool defers() const override { return true; }
    bool finish(Scan& scan, StageReport& report, const ScanReport&, const Scan* next) override {
        held_stamps.push_back(scan.timestamp);
        next_stamps.push_back(next ? next->timestamp : -1.0);
        for (auto& v : scan.valid)  // marks what it finished: its first valid beam goes
            if (v) {
                v = 0;
                break;
            }
        report.points_removed = 1;
        return true;
    }
    std::vector<double> held_stamps, next_stamps;
};

TEST(PipelineNextScan, TheStagesAfterTheHoldingOneRunOnTheFinishedScanInOrder) {
    Pipeline p(withStages({}));
    auto hold = std::make_unique<HoldingStage>();
    HoldingStage* h = hold.get();
    int after_calls = 0;
    auto after = std::make_unique<RecordingStage>("after", true, &after_calls);
    RecordingStage* a = after.get();
    p.add(std::move(hold));
    p.add(std::move(after));
    std::vector<double> out;
    ScanReport done;
    for (int k = 0; k < 4; ++k) {
        Scan s = noisyWall();
        s.timestamp = 10.0 + k;
        const std::size_t valid = s.countValid();
        const ScanReport r = p.process(s);
        EXPECT_TRUE(r.pending);
        EXPECT_EQ(r.stage_count, 0u);      // the holding stage did not run yet
        EXPECT_EQ(s.countValid(), valid);  // the caller's scan is not touched
        if (const Scan* f = p.finished(done)) {
            out.push_back(f->timestamp);
            EXPECT_EQ(done.stage_count, 2u);
            EXPECT_EQ(done.points_out, valid - 1);
            EXPECT_EQ(a->seen_valid, valid - 1);  // the later stage saw the finished scan
        }
    }
    EXPECT_TRUE(p.finish());
    ASSERT_NE(p.finished(done), nullptr);
    out.push_back(p.finished(done)->timestamp);
    EXPECT_EQ(out, (std::vector<double>{10, 11, 12, 13}));
    EXPECT_EQ(h->next_stamps, (std::vector<double>{11, 12, 13, -1}));
    EXPECT_EQ(after_calls, 4);
}

TEST(PipelineNextScan, ABadValueOfTheKeyNamesIt) {
    const StageInfo& denoise = *coreStageRegistry().find("evidence_denoise");
    const StageKey* key = denoise.keyForField("next_scan");
    ASSERT_NE(key, nullptr);
    Pipeline::Params p;
    StageParams& sp = p.at(denoise);
    try {
        key->set(sp.data(), "maybe");
        FAIL() << "no error";
    } catch (const ParameterError& e) {
        EXPECT_EQ(e.field(), "next_scan");
        EXPECT_NE(std::string(e.what()).find("next_scan"), std::string::npos);
    }
    key->set(sp.data(), "true");
    EXPECT_EQ(key->get(sp.data()), "true");
}

}  // namespace
}  // namespace kfd
