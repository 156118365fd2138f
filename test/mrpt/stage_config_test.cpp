// Keys per stage (issue 34): [KFD.<stage>] sections and YAML maps, the flat keys of before read
// with a note, sections of stages the pipeline does not list, a stage listed twice.
#include <mrpt/config/CConfigFileMemory.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/mrpt/config.h"
#include "kfd/stages/core_stages.h"

namespace {

kfd::Pipeline::Params fromIni(const std::string& text, std::vector<std::string>* notes = nullptr) {
    mrpt::config::CConfigFileMemory cfg(text);
    return kfd::loadIni(cfg, "KFD", nullptr, notes);
}

// The message of the ConfigError `text` raises, or "<no error>".
std::string errorOf(const std::string& text) {
    try {
        fromIni(text);
    } catch (const kfd::ConfigError& e) {
        return e.what();
    }
    return "<no error>";
}

TEST(StageConfig, EachStagesSectionSetsThatStagesKeysAndNothingElse) {
    std::vector<std::string> notes;
    const auto p = fromIni(
        "[KFD]\npipeline = distance, keyframe, denoise\n"
        "[KFD.distance]\nmax_range = 30\n[KFD.keyframe]\nwindow = 3\nmax_consecutive_drops = 7\n",
        &notes);
    EXPECT_TRUE(notes.empty());
    EXPECT_EQ(p.get<kfd::DistanceStage>().max_range, 30.0);
    EXPECT_EQ(p.get<kfd::KeyframeStage>().window, 3u);
    EXPECT_EQ(p.get<kfd::KeyframeStage>().max_consecutive_drops, 7u);
    // The guard key of the view selector, declared by both keyframe stages, is untouched.
    EXPECT_EQ(p.get<kfd::ViewKeyframeStage>().max_consecutive_drops,
              kfd::kfdDefaults().get<kfd::ViewKeyframeStage>().max_consecutive_drops);
}

TEST(StageConfig, FlatKeysOfBeforeStillSetTheirStagesWithANoteGivingTheNewSpelling) {
    std::vector<std::string> notes;
    const auto p = fromIni("[KFD]\nmax_range = 30\nmax_consecutive_drops = 7\nrings = 4\n", &notes);
    EXPECT_EQ(p.get<kfd::DistanceStage>().max_range, 30.0);
    EXPECT_EQ(p.get<kfd::ViewKeyframeStage>().max_consecutive_drops, 7u);
    EXPECT_EQ(p.get<kfd::KeyframeStage>().max_consecutive_drops, 7u);  // as before
    ASSERT_EQ(notes.size(), 1u);
    const std::string& n = notes[0];
    EXPECT_NE(n.find("3 flat keys in [KFD], read for this release"), std::string::npos) << n;
    EXPECT_NE(n.find("[KFD.distance] max_range"), std::string::npos) << n;
    EXPECT_NE(n.find("[KFD.view_keyframe] max_consecutive_drops"), std::string::npos) << n;
    EXPECT_NE(n.find("rings: no stage of the pipeline has them"), std::string::npos) << n;
}

TEST(StageConfig, ASectionOfAStageThePipelineDoesNotListIsAnErrorNamingBoth) {
    const std::string m = errorOf("[KFD]\n[KFD.keyframe]\nwindow = 3\n");
    EXPECT_NE(m.find("[KFD.keyframe]: stage 'keyframe' is not in the pipeline (odometry_check, "
                     "distance, track, view_keyframe, evidence_denoise)"),
              std::string::npos)
        << m;
    const std::string u = errorOf("[KFD]\n[KFD.median]\nwindow = 3\n");
    EXPECT_NE(u.find("no stage 'median'"), std::string::npos) << u;
}

TEST(StageConfig, AKeyTheStageDoesNotDeclareIsAnErrorListingItsKeys) {
    const std::string m = errorOf("[KFD]\n[KFD.distance]\nwindow = 3\n");
    EXPECT_NE(m.find("config key 'window': [KFD.distance]: not a key of stage distance (its "
                     "keys: min_range, max_range)"),
              std::string::npos)
        << m;
    const std::string v = errorOf("[KFD]\n[KFD.distance]\nmax_range = -3\n");
    EXPECT_NE(v.find("config key 'max_range': [KFD.distance]"), std::string::npos) << v;
}

TEST(StageConfig, AStageListedTwiceIsConfiguredAsItsSecondInstance) {
    const auto p = fromIni(
        "[KFD]\npipeline = distance, evidence_denoise, distance\n"
        "[KFD.distance]\nmax_range = 30\n[KFD.distance_2]\nmax_range = 8\n");
    EXPECT_EQ(p.get<kfd::DistanceStage>().max_range, 30.0);
    const auto* second = p.find("distance_2");
    ASSERT_NE(second, nullptr);
    EXPECT_EQ(static_cast<const kfd::DistanceFilter::Params*>(second->data())->max_range, 8.0);
    // Printed and read back: the same two sections.
    const std::string ini = kfd::toIni(p);
    EXPECT_NE(ini.find("[KFD.distance_2]\nmin_range = 0\nmax_range = 8\n"), std::string::npos)
        << ini;
    EXPECT_EQ(kfd::toIni(fromIni(ini)), ini);
    EXPECT_NE(errorOf("[KFD]\n[KFD.distance_2]\nmax_range = 8\n").find("not in the pipeline"),
              std::string::npos);
}

TEST(StageConfig, YamlMapsPerStageReadAsTheIniSections) {
    std::vector<std::string> notes;
    const auto y = kfd::loadYamlText(
        "kfd:\n  pipeline: [distance, keyframe]\n  distance:\n    max_range: 30\n"
        "  keyframe:\n    window: 3\n",
        "", nullptr, &notes);
    EXPECT_TRUE(notes.empty());
    const auto i = fromIni(
        "[KFD]\npipeline = distance, keyframe\n[KFD.distance]\nmax_range = 30\n"
        "[KFD.keyframe]\nwindow = 3\n");
    EXPECT_EQ(kfd::toIni(y), kfd::toIni(i));
    try {
        kfd::loadYamlText("kfd:\n  denoise:\n    rings: 4\n");
        FAIL() << "no error";
    } catch (const kfd::ConfigError& e) {
        EXPECT_NE(
            std::string(e.what()).find("kfd: denoise:: stage 'denoise' is not in the pipeline"),
            std::string::npos)
            << e.what();
    }
    EXPECT_THROW(kfd::loadYamlText("kfd:\n  distance:\n    x:\n      y: 1\n"), kfd::ConfigError);
}

TEST(StageConfig, TheDefaultFileIsWrittenPerStageAndLoadsWithoutANote) {
    std::vector<std::string> notes;
    const auto p = fromIni(kfd::kfdDefaultIni(), &notes);
    EXPECT_TRUE(notes.empty()) << notes.front();
    EXPECT_EQ(kfd::toIni(p), kfd::toIni(kfd::kfdDefaults()));
    EXPECT_NE(std::string(kfd::kfdDefaultIni()).find("[KFD.evidence_denoise]"), std::string::npos);
}

}  // namespace
