#include "kfd/core/pipeline.h"

#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/core/denoise_stage.h"
#include "test_scans.h"

namespace kfd {
namespace {

std::vector<std::string> stageNames(const Pipeline& p) {
    std::vector<std::string> names;
    for (const auto& s : p.stages()) names.emplace_back(s->name());
    return names;
}

// The paper's method (the reference denoiser): the expectations below follow Algorithm 2.
Pipeline::Params paper() {
    Pipeline::Params p;
    p.get<DenoiseStage>().variant = DenoiseVariant::Reference;
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
        seen_denoised = chain.find<Denoiser::Result>() != nullptr;
        return keep_;
    }
    void observeDropped(const Scan& scan) override {
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

TEST(Pipeline, DefaultStageOrder) {
    const Pipeline p;
    EXPECT_EQ(stageNames(p), (std::vector<std::string>{"distance", "keyframe", "denoise"}));
    EXPECT_EQ(p.params().stages, (std::vector<std::string>{"distance", "keyframe", "denoise"}));
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

TEST(Pipeline, RepeatedStageThrows) {
    EXPECT_THROW(Pipeline(withStages({"distance", "keyframe", "distance"})), kfd::ParameterError);
    EXPECT_THROW(Pipeline(withStages({"denoise", "denoise"})), kfd::ParameterError);
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
    p.get<kfd::DenoiseStage>().filter.m_threshold = 0;
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
    EXPECT_NE(r.find<kfd::Denoiser::Result>(), nullptr);
    EXPECT_EQ(r.points_in, 121u);
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().valid_in, 121u);
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().removed_out_of_range, 1u);
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().removed_non_finite, 1u);
    EXPECT_EQ(r.findOrDefault<kfd::Denoiser::Result>().points_in, 119u);
    EXPECT_EQ(r.findOrDefault<kfd::Denoiser::Result>().points_removed, 3u);
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
    EXPECT_EQ(r.dropped_by, "keyframe");
    EXPECT_NE(r.find<kfd::KeyframeDecision>(), nullptr);
    EXPECT_EQ(r.findOrDefault<kfd::KeyframeDecision>().reason, KeyframeReason::Covered);
    EXPECT_EQ(r.find<kfd::Denoiser::Result>(), nullptr);
    EXPECT_EQ(r.findOrDefault<kfd::Denoiser::Result>().points_removed, 0u);
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
        EXPECT_NE(r.find<kfd::Denoiser::Result>(), nullptr);
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
    EXPECT_EQ(r.findOrDefault<kfd::Denoiser::Result>().points_in, 121u);
    EXPECT_GE(r.findOrDefault<kfd::Denoiser::Result>().points_removed, 1u);
    EXPECT_EQ(r.findOrDefault<kfd::DistanceFilter::Result>().valid_in,
              121u - r.findOrDefault<kfd::Denoiser::Result>().points_removed);
}

TEST(Pipeline, CustomStageViaAdd) {
    Pipeline p;
    int calls = 0;
    auto stage = std::make_unique<RecordingStage>("recorder", true, &calls);
    RecordingStage* rec = stage.get();
    p.add(std::move(stage));
    EXPECT_EQ(stageNames(p),
              (std::vector<std::string>{"distance", "keyframe", "denoise", "recorder"}));
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
    // As the gate left it: after the distance stage (the wall's 121 returns, 30-150, less 60, 61).
    EXPECT_EQ(a->observed_valid, 119u);
}

/// Drops every scan whose odometry is not a whole number of metres (the "keyframes").
class WholeMetreGate : public Stage {
  public:
    const char* name() const override { return "gate"; }
    bool process(Scan& scan, StageReport&, const ScanReport&) override {
        return std::abs(scan.odometry->x - std::round(scan.odometry->x)) < 1e-9;
    }
};

TEST(Pipeline, TheDenoiserUsesTheScanDroppedJustBeforeAKeyframe) {
    // Keyframes 1 m apart (a wide keyframe margin supports a spike 0.12 m before the wall);
    // the scan dropped 2 cm before the second keyframe sees through it (issue 25).
    for (const std::size_t kept : {0u, 1u}) {
        Pipeline p(withStages({}));
        DenoiseStage::Params dp;
        dp.evidence.sigma_m = 0.01;
        dp.evidence.temporal_scans = kept;
        p.add(std::make_unique<WholeMetreGate>());
        p.add(std::make_unique<DenoiseStage>(dp));
        auto wall = [](double x) {
            Scan s = test::flatWall(361, test::deg2rad(150.0), 4.0 - x);
            s.odometry = Pose2D{x, 0.0, 0.0};
            return s;
        };
        Scan a = wall(0.0), dropped = wall(0.98), b = wall(1.0);
        test::insertSpike(b, 180, 2.88);
        EXPECT_TRUE(p.process(a).keep);
        EXPECT_FALSE(p.process(dropped).keep);
        EXPECT_TRUE(p.process(b).keep);
        EXPECT_EQ(b.valid[180], kept > 0 ? 0 : 1) << kept;
    }
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
    EXPECT_EQ(r.find<kfd::Denoiser::Result>(), nullptr);
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
    EXPECT_NE(r.find<kfd::Denoiser::Result>(), nullptr);
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
    auto params = withStages({"distance", "denoise"});
    params.get<kfd::DistanceStage>().max_range = 5.0;  // the wall beyond 5 m goes
    params.get<kfd::DenoiseStage>().variant = DenoiseVariant::RangeAware;
    Pipeline p(params);
    Scan scan = noisyWall();
    const auto r = p.process(scan);
    EXPECT_EQ(r.findOrDefault<kfd::Denoiser::Result>().variant, DenoiseVariant::RangeAware);
    EXPECT_GT(r.findOrDefault<kfd::DistanceFilter::Result>().removed_out_of_range, 1u);
    for (std::size_t i = 0; i < scan.size(); ++i) {
        if (scan.valid[i]) {
            EXPECT_LE(scan.range[i], 5.0f) << i;
        }
    }
}

}  // namespace
}  // namespace kfd
