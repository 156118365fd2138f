// Stages found by name: the registry, the stages' own keys, typed parameters and reports.
#include "kfd/pipeline/stage_registry.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/pipeline/pipeline.h"
#include "kfd/stages/core_stages.h"
#include "test_scans.h"

namespace kfd {
namespace {

std::vector<std::string> keyNames(const StageInfo& s) {
    std::vector<std::string> v;
    for (const auto& k : s.keys) v.push_back(k.name);
    return v;
}

// test::noisyWall: outliers at beams 50, 100 and 130, beam 60 out of range and beam 61 NaN.
using test::noisyWall;

TEST(StageRegistry, CoreRegistryHoldsThePapersStagesThenKfds) {
    const auto& r = coreStageRegistry();
    EXPECT_EQ(r.names(),
              "distance, keyframe, denoise, view_keyframe, range_aware_denoise, "
              "evidence_denoise, odometry_check, fuse, track");
    ASSERT_EQ(r.stages().size(), 9u);
    for (const auto& s : r.stages()) {
        EXPECT_FALSE(s.help.empty()) << s.name;
        EXPECT_FALSE(s.keys.empty()) << s.name;
    }
    EXPECT_EQ(r.find("motion"), nullptr);  // the baselines are not in the core
    EXPECT_NE(r.find("keyframe"), nullptr);
}

TEST(StageRegistry, EachStageOwnsItsKeys) {
    const auto& r = coreStageRegistry();
    EXPECT_EQ(keyNames(*r.find("distance")), (std::vector<std::string>{"min_range", "max_range"}));
    const std::vector<std::string> guards{"max_consecutive_drops", "max_interval_s",
                                          "max_translation_m", "max_rotation_deg"};
    auto with = [](std::vector<std::string> v, const std::vector<std::string>& more) {
        v.insert(v.end(), more.begin(), more.end());
        return v;
    };
    // The paper's stages declare the paper's keys (plus kfd's guards, off in the presets).
    EXPECT_EQ(keyNames(*r.find("keyframe")), with({"bins", "window", "p_pair"}, guards));
    EXPECT_EQ(keyNames(*r.find("denoise")),
              (std::vector<std::string>{"rings", "ring_r_max", "angle_gap_factor",
                                        "merge_distance_m", "m_threshold"}));
    // kfd's stages their own.
    EXPECT_EQ(keyNames(*r.find("view_keyframe")),
              with({"view_samples", "view_tolerance_m", "view_tolerance_deg", "max_view_change",
                    "change_tolerance_m", "change_tolerance_ratio", "max_changed_fraction",
                    "degeneracy_ratio", "corridor_translation_m", "corridor_rotation_deg",
                    "corridor_interval_s", "max_track_disagreement"},
                   guards));
    EXPECT_EQ(keyNames(*r.find("range_aware_denoise")),
              (std::vector<std::string>{"angle_gap_factor", "m_threshold", "jump_lambda_deg",
                                        "jump_sigma_m", "min_object_size_m", "min_points_floor"}));
    EXPECT_EQ(keyNames(*r.find("evidence_denoise")),
              (std::vector<std::string>{"min_object_size_m",
                                        "incidence_deg",
                                        "sigma_m",
                                        "max_gap_beams",
                                        "max_small_points",
                                        "dropout_fragments",
                                        "temporal",
                                        "pose_trans_error_m",
                                        "pose_rot_error_deg",
                                        "motion_error_fraction",
                                        "max_removed_fraction",
                                        "max_confirmed_fraction",
                                        "confirm_support",
                                        "temporal_scans",
                                        "next_scan",
                                        "veil",
                                        "track_alignment",
                                        "track_raw_alignment",
                                        "track_keyframe_start",
                                        "tracked_refine_iterations",
                                        "tracked_refine_samples",
                                        "spikes",
                                        "spike_object_support",
                                        "keep_surfaces",
                                        "surface_min_beams",
                                        "surface_sigmas"}));
    EXPECT_EQ(keyNames(*r.find("odometry_check")),
              (std::vector<std::string>{"frozen_changed_fraction", "jump_margin"}));
}

TEST(StageRegistry, KeysParseRangeCheckAndPrintBack) {
    const StageInfo& kf = *coreStageRegistry().find("keyframe");
    PipelineParams p;
    StageParams& sp = p.at(kf);
    const StageKey* window = kf.keyForField("window");
    ASSERT_NE(window, nullptr);
    window->set(sp.data(), "3");  // the config layer hands over trimmed text
    EXPECT_EQ(p.get<KeyframeStage>().window, 3u);
    EXPECT_EQ(window->get(sp.data()), "3");
    try {
        window->set(sp.data(), "0");
        FAIL() << "window = 0 accepted";
    } catch (const ParameterError& e) {
        EXPECT_EQ(e.field(), "window");
        EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
    }
    EXPECT_THROW(window->set(sp.data(), "2.5"), ParameterError);
    EXPECT_THROW(window->set(sp.data(), "eight"), ParameterError);
    EXPECT_EQ(p.get<KeyframeStage>().window, 3u);  // a rejected value changes nothing
    const StageKey* p_pair = kf.keyForField("p_pair");
    ASSERT_NE(p_pair, nullptr);
    p_pair->set(sp.data(), "0.99");
    EXPECT_DOUBLE_EQ(p.get<KeyframeStage>().p_pair, 0.99);
    EXPECT_THROW(p_pair->set(sp.data(), "0"), ParameterError);  // (0, 1]: open below
    EXPECT_THROW(p_pair->set(sp.data(), "inf"), ParameterError);
}

TEST(StageRegistry, MaxRangeKeyTakesScanOrANumber) {
    const StageInfo& d = *coreStageRegistry().find("distance");
    PipelineParams p;
    StageParams& sp = p.at(d);
    const StageKey* max = d.keyForField("max_range");
    ASSERT_NE(max, nullptr);
    EXPECT_EQ(max->get(sp.data()), "scan");  // the default: the scan's own maximum
    max->set(sp.data(), "25");
    EXPECT_DOUBLE_EQ(p.get<DistanceStage>().max_range, 25.0);
    EXPECT_EQ(max->get(sp.data()), "25");
    max->set(sp.data(), "scan");
    EXPECT_TRUE(std::isinf(p.get<DistanceStage>().max_range));
    EXPECT_THROW(max->set(sp.data(), "inf"), ParameterError);
    EXPECT_THROW(max->set(sp.data(), "0"), ParameterError);
    EXPECT_THROW(max->set(sp.data(), "Scan"), ParameterError);
    EXPECT_NE(max->range.find("scan"), std::string::npos) << max->range;
}

// `selector` and `variant` choose among stages of one role; every option names a registered
// stage, and a stage belongs to at most one role.
TEST(StageRegistry, ChoiceKeysNameTheStagesOfARole) {
    const auto& r = coreStageRegistry();
    const StageChoice* selector = r.choice("selector");
    ASSERT_NE(selector, nullptr);
    EXPECT_EQ(selector->values(), "paper, view");
    EXPECT_EQ(selector->find("paper")->stage, "keyframe");
    EXPECT_EQ(selector->find("view")->stage, "view_keyframe");
    EXPECT_EQ(selector->find("histogram"), nullptr);
    EXPECT_EQ(selector->listedIn({"distance", "view_keyframe", "keyframe"})->value, "view");
    EXPECT_EQ(selector->listedIn({"distance", "evidence_denoise"}), nullptr);
    const StageChoice* variant = r.choice("variant");
    ASSERT_NE(variant, nullptr);
    EXPECT_EQ(variant->values(), "reference, range_aware, evidence");
    EXPECT_EQ(r.choiceOfStage("evidence_denoise"), variant);
    EXPECT_EQ(r.choiceOfStage("denoise"), variant);
    EXPECT_EQ(r.choiceOfStage("distance"), nullptr);
    StageRegistry other;
    registerCoreStages(other);
    EXPECT_THROW(other.addChoice({"selector", "again", {}}), Error);
    EXPECT_THROW(other.addChoice({"mode", "unknown stage", {{"x", "no_such_stage"}}}), Error);
}

TEST(StageRegistry, RejectsRepeatedAndEmptyNames) {
    StageRegistry r;
    registerCoreStages(r);
    EXPECT_THROW(r.add<KeyframeStage>(), Error);
    StageInfo nameless;
    EXPECT_THROW(r.add(nameless), Error);
    EXPECT_EQ(r.stages().size(), 9u);
}

TEST(PipelineParams, TypedAccessCopiesAndDefaults) {
    PipelineParams p;
    EXPECT_TRUE(p.entries().empty());
    const PipelineParams& cp = p;
    EXPECT_EQ(cp.get<KeyframeStage>().window, KeyframeSelector::Params{}.window);  // defaults
    EXPECT_TRUE(p.entries().empty());  // reading does not create
    p.get<KeyframeStage>().window = 3;
    p.get<DenoiseStage>().m_threshold = 4;
    ASSERT_EQ(p.entries().size(), 2u);
    PipelineParams copy = p;
    p.get<KeyframeStage>().window = 4;  // deep copy: the copy keeps its own value
    EXPECT_EQ(copy.get<KeyframeStage>().window, 3u);
    EXPECT_EQ(copy.get<DenoiseStage>().m_threshold, 4u);
    copy = p;
    EXPECT_EQ(copy.get<KeyframeStage>().window, 4u);
}

TEST(PipelineParams, WrongTypeUnderAStageNameThrows) {
    StageInfo impostor;  // claims the name "keyframe" with other parameters
    impostor.name = "keyframe";
    impostor.defaults = [] { return std::make_unique<StageParamsOf<int>>(); };
    PipelineParams p;
    p.at(impostor);
    EXPECT_THROW(p.get<KeyframeStage>(), Error);
    EXPECT_THROW(Pipeline{p}, Error);
}

TEST(ScanReport, OneStageReportPerStageWithTypedDiagnostics) {
    Pipeline pipe;
    Scan scan = noisyWall();
    const ScanReport r = pipe.process(scan);
    ASSERT_EQ(r.stage_count, 3u);
    EXPECT_STREQ(r.stage_reports[0].name, "distance");
    EXPECT_STREQ(r.stage_reports[1].name, "view_keyframe");
    EXPECT_STREQ(r.stage_reports[2].name, "evidence_denoise");
    const StageReport* d = r.stage("distance");
    ASSERT_NE(d, nullptr);
    ASSERT_NE(d->diagnostics<DistanceFilter::Result>(), nullptr);
    EXPECT_EQ(d->diagnostics<KeyframeDecision>(), nullptr);  // typed: another type is absent
    EXPECT_EQ(d->points_removed, 2u);
    EXPECT_FALSE(d->noise);
    EXPECT_TRUE(r.stage("evidence_denoise")->noise);
    EXPECT_EQ(r.stage("evidence_denoise")->points_removed, r.find<DenoiseResult>()->points_removed);
    std::size_t removed = 0;
    double us = 0.0;
    for (const auto& s : r) {
        EXPECT_FALSE(s.dropped);
        EXPECT_GE(s.microseconds, 0.0);
        removed += s.points_removed;
        us += s.microseconds;
    }
    EXPECT_EQ(removed, r.points_in - r.points_out);
    EXPECT_LE(us, r.microseconds);
    EXPECT_EQ(r.noiseRemoved(), r.find<DenoiseResult>()->points_removed);
    EXPECT_EQ(r.stage("motion"), nullptr);
}

TEST(ScanReport, TheDroppingStageIsMarkedAndLaterStagesAreAbsent) {
    Pipeline pipe;
    Scan a = noisyWall();
    pipe.process(a);
    Scan b = noisyWall();
    const ScanReport r = pipe.process(b);
    ASSERT_FALSE(r.keep);
    ASSERT_EQ(r.stage_count, 2u);
    EXPECT_TRUE(r.stage("view_keyframe")->dropped);
    EXPECT_EQ(r.stage("evidence_denoise"), nullptr);
    EXPECT_EQ(r.find<DenoiseResult>(), nullptr);
    EXPECT_EQ(r.findOrDefault<DenoiseResult>().points_removed, 0u);
    const ScanReport copy = r;  // a plain value: diagnostics are copied, not referenced
    Scan c = noisyWall();
    pipe.reset();
    pipe.process(c);
    EXPECT_EQ(copy.find<KeyframeDecision>()->reason, KeyframeReason::Covered);
}

TEST(Pipeline, InitializeKeepsTheRegistryItWasBuiltWith) {
    StageRegistry only_distance;
    only_distance.add<DistanceStage>();
    PipelineParams p;
    p.stages = {"distance"};
    Pipeline pipe(p, only_distance);
    EXPECT_EQ(&pipe.registry(), &only_distance);
    p.stages = {"distance", "keyframe"};
    EXPECT_THROW(pipe.initialize(p), ParameterError);  // keyframe is not in that registry
    EXPECT_NO_THROW(pipe.initialize(p, coreStageRegistry()));
    EXPECT_EQ(pipe.stages().size(), 2u);
}

}  // namespace
}  // namespace kfd
