// Configuration loaders: every shipped config, key validation, INI/YAML agreement.
#include <gtest/gtest.h>
#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/containers/yaml.h>
#include <algorithm>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "kfd/algorithms/evidence_filter.h"
#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/default_stages.h"
#include "kfd/pipeline/stage_keys.h"
#include "kfd/stages/core_stages.h"
#include "kfd/stages/keyframe_stage.h"
#include "test_files.h"

namespace {

kfd::Pipeline::Params fromIniText(const std::string& text) {
    mrpt::config::CConfigFileMemory cfg(text);
    return kfd::loadIni(cfg);
}

std::string errorKey(const std::string& text) {
    try {
        fromIniText(text);
    } catch (const kfd::ConfigError& e) {
        return e.key();
    }
    return "<no error>";
}

}  // namespace

TEST(Config, EveryShippedConfigLoads) {
    std::size_t n = 0;
    for (const auto& entry : std::filesystem::directory_iterator(KFD_SHARE_DIR)) {
        SCOPED_TRACE(entry.path().string());
        EXPECT_NO_THROW(kfd::loadConfigFile(entry.path().string()));
        ++n;
    }
    EXPECT_GE(n, 4u);  // default.ini, default.yaml and the two paper presets
}

// The lines of toIni(a) that differ from toIni(b).
std::vector<std::string> differingLines(const kfd::Pipeline::Params& a,
                                        const kfd::Pipeline::Params& b) {
    std::vector<std::string> out;
    std::istringstream x(kfd::toIni(a)), y(kfd::toIni(b));
    for (std::string l, m; std::getline(x, l) && std::getline(y, m);)
        if (l != m) out.push_back(l);
    return out;
}

// A file changes only the keys it sets: the others keep kfd's defaults (what runs without a
// file), in .ini and YAML, kfd_node's ~config included (it reads files the same way).
TEST(Config, AFileChangesOnlyTheKeysItSets) {
    const auto ini = fromIniText("[KFD]\n[KFD.evidence_denoise]\nnext_scan = true\n");
    EXPECT_EQ(differingLines(ini, kfd::kfdDefaults()),
              (std::vector<std::string>{"next_scan = true"}));
    EXPECT_EQ(ini.stages, kfd::kfdDefaults().stages);  // odometry_check kept
    const auto yaml = kfd::loadYamlText("kfd:\n  view_keyframe:\n    max_view_change: 0.5\n");
    EXPECT_EQ(differingLines(yaml, kfd::kfdDefaults()),
              (std::vector<std::string>{"max_view_change = 0.5"}));
    // Over the stages' own defaults when asked (what kfdDefaults() itself does).
    const kfd::Pipeline::Params plain;
    mrpt::config::CConfigFileMemory cfg(std::string("[KFD]\nnext_scan = true\n"));
    EXPECT_EQ(kfd::loadIni(cfg, "KFD", &plain).stages, plain.stages);
}

// Every shipped preset sets the keys whose kfd default differs from the stage's own, so it
// reads the same over either (the paper presets are the paper's whatever the base).
TEST(Config, EveryShippedPresetReadsTheSameOverEitherBase) {
    const kfd::Pipeline::Params plain;
    std::size_t n = 0;
    for (const std::string& dir :
         {std::string(KFD_SHARE_DIR), std::string(KFD_SOURCE_DIR) + "/share/kfd-icp-slam"})
        for (const auto& entry : std::filesystem::directory_iterator(dir)) {
            SCOPED_TRACE(entry.path().string());
            const std::string text = kfd::test::fileBytes(entry.path().string());
            kfd::Pipeline::Params a, b;
            if (entry.path().extension() == ".yaml") {
                a = kfd::loadYamlText(text, "", &plain);
                b = kfd::loadYamlText(text);
            } else {
                mrpt::config::CConfigFileMemory cfg(text);
                a = kfd::loadIni(cfg, "KFD", &plain);
                b = kfd::loadIni(cfg, "KFD");
            }
            EXPECT_EQ(kfd::toIni(a), kfd::toIni(b));
            ++n;
        }
    EXPECT_GE(n, 8u);  // share/kfd (4) and share/kfd-icp-slam (4)
}

TEST(Config, PaperPresetsHoldThePublishedValues) {
    const auto a = kfd::loadConfigFile(std::string(KFD_SHARE_DIR) + "/paper-mit-0.752.ini");
    EXPECT_EQ(a.get<kfd::KeyframeStage>().window, 8u);
    EXPECT_EQ(a.get<kfd::KeyframeStage>().bins, 20u);
    EXPECT_DOUBLE_EQ(a.get<kfd::KeyframeStage>().p_pair, 0.985);
    const auto b = kfd::loadConfigFile(std::string(KFD_SHARE_DIR) + "/paper-mit-0.575.ini");
    EXPECT_EQ(b.get<kfd::KeyframeStage>().window, 9u);
    EXPECT_EQ(b.get<kfd::KeyframeStage>().bins, 15u);
    EXPECT_DOUBLE_EQ(b.get<kfd::KeyframeStage>().p_pair, 0.99);
    for (const auto& p : {a, b}) {
        EXPECT_EQ(p.get<kfd::DenoiseStage>().clustering.rings.rings, 5u);
        EXPECT_DOUBLE_EQ(p.get<kfd::DenoiseStage>().clustering.angle_gap_factor, 10.0);
        EXPECT_EQ(p.get<kfd::DenoiseStage>().m_threshold, 10u);
        // The paper's three stages, and nothing of kfd's.
        EXPECT_EQ(p.stages, (std::vector<std::string>{"distance", "keyframe", "denoise"}));
        // The published method has no guards.
        EXPECT_EQ(p.get<kfd::KeyframeStage>().max_consecutive_drops, 0u);
        EXPECT_EQ(p.get<kfd::KeyframeStage>().max_interval_s, 0.0);
        EXPECT_EQ(p.get<kfd::KeyframeStage>().max_translation_m, 0.0);
        EXPECT_EQ(p.get<kfd::KeyframeStage>().max_rotation_deg, 0.0);
    }
}

TEST(Config, YamlAndIniDefaultsAgree) {
    const auto ini = kfd::loadConfigFile(std::string(KFD_SHARE_DIR) + "/default.ini");
    const auto yml = kfd::loadConfigFile(std::string(KFD_SHARE_DIR) + "/default.yaml");
    EXPECT_EQ(kfd::toIni(ini), kfd::toIni(yml));
    EXPECT_EQ(ini.stages, yml.stages);
}

TEST(Config, KfdDefaultsAreDefaultIniCompiledIn) {
    const auto ini = kfd::loadConfigFile(std::string(KFD_SHARE_DIR) + "/default.ini");
    EXPECT_EQ(kfd::toIni(kfd::kfdDefaults()), kfd::toIni(ini));
    EXPECT_EQ(kfd::kfdDefaults().stages,
              (std::vector<std::string>{"odometry_check", "distance", "track", "view_keyframe",
                                        "evidence_denoise"}));
}

TEST(Config, EveryShippedNonPaperPresetUsesTheViewSelectorAndTheEvidenceDenoiser) {
    namespace fs = std::filesystem;
    std::size_t seen = 0;
    for (const char* dir : {KFD_SHARE_DIR, KFD_SHARE_DIR "/../kfd-icp-slam"})
        for (const auto& e : fs::directory_iterator(dir)) {
            if (e.path().extension() != ".ini" && e.path().extension() != ".yaml") continue;
            SCOPED_TRACE(e.path().string());
            const auto p = kfd::loadConfigFile(e.path().string());
            const bool paper = e.path().filename().string().rfind("paper-", 0) == 0;
            auto lists = [&p](const char* stage) { return p.lists(stage); };
            EXPECT_EQ(lists("denoise"), paper);
            EXPECT_EQ(lists("keyframe"), paper);
            EXPECT_EQ(lists("evidence_denoise"), !paper);
            EXPECT_EQ(lists("view_keyframe"), !paper);
            ++seen;
        }
    EXPECT_GE(seen, 8u);
}

TEST(Config, MissingKeysKeepKfdsDefaults) {
    const auto p = fromIniText("[KFD]\nwindow = 3\n");
    EXPECT_EQ(p.get<kfd::KeyframeStage>().window, 3u);
    EXPECT_EQ(kfd::toIni(p), kfd::toIni([] {
                  kfd::Pipeline::Params d = kfd::kfdDefaults();
                  d.get<kfd::KeyframeStage>().window = 3;
                  return d;
              }()));
}

TEST(Config, UnknownKeyIsRejectedByName) {
    EXPECT_EQ(errorKey("[KFD]\nwindw = 3\n"), "windw");
    try {
        fromIniText("[KFD]\nwindw = 3\n");
        FAIL();
    } catch (const kfd::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("windw"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("window"), std::string::npos);  // lists known keys
    }
}

TEST(Config, OutOfRangeValuesNameTheKey) {
    EXPECT_EQ(errorKey("[KFD]\nwindow = 0\n"), "window");
    EXPECT_EQ(errorKey("[KFD]\np_pair = 1.5\n"), "p_pair");
    EXPECT_EQ(errorKey("[KFD]\np_pair = 0\n"), "p_pair");
    EXPECT_EQ(errorKey("[KFD]\nbins = 1\n"), "bins");
    EXPECT_EQ(errorKey("[KFD]\nmin_range = -1\n"), "min_range");
    EXPECT_EQ(errorKey("[KFD]\nrings = 0\n"), "rings");
    EXPECT_EQ(errorKey("[KFD]\nmax_rotation_deg = 400\n"), "max_rotation_deg");
    EXPECT_EQ(errorKey("[KFD]\nmin_range = 5\nmax_range = 2\n"), "max_range");
}

TEST(Config, MalformedValuesNameTheKey) {
    EXPECT_EQ(errorKey("[KFD]\nwindow = eight\n"), "window");
    EXPECT_EQ(errorKey("[KFD]\nwindow = 2.5\n"), "window");
    EXPECT_EQ(errorKey("[KFD]\nmax_range = 30m\n"), "max_range");
    EXPECT_EQ(errorKey("[KFD]\nvariant = fancy\n"), "variant");
    EXPECT_EQ(errorKey("[KFD]\npipeline = distance, smooth\n"), "pipeline");
    EXPECT_EQ(errorKey("[KFD]\npipeline = keyframe, keyframe\n"),
              "<no error>");  // listed twice: two instances
}

TEST(Config, PipelineOrderIsRead) {
    const auto p = fromIniText("[KFD]\npipeline = distance, denoise\n");
    ASSERT_EQ(p.stages.size(), 2u);
    EXPECT_EQ(p.stages[0], "distance");
    EXPECT_EQ(p.stages[1], "denoise");
}

TEST(Config, OtherSectionsAreIgnoredButTheSectionMustExist) {
    EXPECT_NO_THROW(fromIniText("[ICP]\nfoo = 1\n[KFD]\nwindow = 2\n"));
    EXPECT_THROW(fromIniText("[ICP]\nfoo = 1\n"), kfd::ConfigError);
}

TEST(Config, YamlTopLevelOrKfdMap) {
    auto top = mrpt::containers::yaml::FromText("window: 4\nvariant: range_aware\n");
    EXPECT_EQ(kfd::loadYaml(top).get<kfd::KeyframeStage>().window, 4u);
    auto nested = mrpt::containers::yaml::FromText("kfd:\n  window: 5\n");
    EXPECT_EQ(kfd::loadYaml(nested).get<kfd::KeyframeStage>().window, 5u);
    auto bad = mrpt::containers::yaml::FromText("kfd:\n  windoww: 5\n");
    try {
        kfd::loadYaml(bad);
        FAIL();
    } catch (const kfd::ConfigError& e) {
        EXPECT_EQ(e.key(), "windoww");
    }
}

TEST(Config, FileErrorsAreClear) {
    EXPECT_THROW(kfd::loadConfigFile("/nonexistent/kfd.ini"), kfd::ConfigError);
    const auto tmp = std::filesystem::temp_directory_path() / "kfd_config_test.toml";
    std::ofstream(tmp) << "window = 3\n";
    EXPECT_THROW(kfd::loadConfigFile(tmp.string()), kfd::ConfigError);
    std::filesystem::remove(tmp);
}

TEST(Config, PrintedConfigReadsBackTheSame) {
    const auto p = kfd::loadConfigFile(std::string(KFD_SHARE_DIR) + "/paper-mit-0.575.ini");
    EXPECT_EQ(kfd::toIni(fromIniText(kfd::toIni(p))), kfd::toIni(p));
}

TEST(Config, EveryKeyIsDocumented) {
    for (const auto& k : kfd::configKeys()) {
        EXPECT_FALSE(k.help.empty()) << k.name;
        EXPECT_FALSE(k.range.empty()) << k.name;
    }
}

TEST(Config, RadiusAndSorKeysLoadAndAreRangeChecked) {
    // Built-in defaults when absent.
    const auto d = fromIniText("[KFD]\nwindow = 2\n");
    EXPECT_EQ(d.get<kfd::RadiusStage>().radius_m, 0.3);
    EXPECT_EQ(d.get<kfd::RadiusStage>().min_neighbors, 3u);
    EXPECT_EQ(d.get<kfd::SorStage>().k, 8u);
    EXPECT_EQ(d.get<kfd::SorStage>().std_mul, 1.0);

    const auto p = fromIniText(
        "[KFD]\npipeline = distance, radius, sor\nradius_m = 0.45\nradius_min_neighbors = 5\n"
        "sor_k = 12\nsor_std_mul = 2.5\n");
    EXPECT_EQ(p.stages, (std::vector<std::string>{"distance", "radius", "sor"}));
    EXPECT_DOUBLE_EQ(p.get<kfd::RadiusStage>().radius_m, 0.45);
    EXPECT_EQ(p.get<kfd::RadiusStage>().min_neighbors, 5u);
    EXPECT_EQ(p.get<kfd::SorStage>().k, 12u);
    EXPECT_DOUBLE_EQ(p.get<kfd::SorStage>().std_mul, 2.5);
    EXPECT_EQ(kfd::toIni(fromIniText(kfd::toIni(p))), kfd::toIni(p));  // printed and read back
    EXPECT_NE(kfd::toIni(p).find("radius_min_neighbors = 5"), std::string::npos);

    auto yml = mrpt::containers::yaml::FromText(
        "kfd:\n  pipeline: [distance, sor]\n  sor_k: 4\n  sor_std_mul: 0\n  radius_m: 1\n");
    const auto y = kfd::loadYaml(yml);
    EXPECT_EQ(y.stages, (std::vector<std::string>{"distance", "sor"}));
    EXPECT_EQ(y.get<kfd::SorStage>().k, 4u);
    EXPECT_EQ(y.get<kfd::SorStage>().std_mul, 0.0);
    EXPECT_EQ(y.get<kfd::RadiusStage>().radius_m, 1.0);

    // Limits are inclusive where documented.
    EXPECT_NO_THROW(fromIniText("[KFD]\nradius_m = 100\nradius_min_neighbors = 1\n"));
    EXPECT_NO_THROW(fromIniText("[KFD]\nsor_k = 1\nsor_std_mul = 0\n"));
    EXPECT_NO_THROW(fromIniText("[KFD]\nsor_k = 1000\nsor_std_mul = 100\n"));

    EXPECT_EQ(errorKey("[KFD]\nradius_m = 0\n"), "radius_m");
    EXPECT_EQ(errorKey("[KFD]\nradius_m = -0.3\n"), "radius_m");
    EXPECT_EQ(errorKey("[KFD]\nradius_m = 100.5\n"), "radius_m");
    EXPECT_EQ(errorKey("[KFD]\nradius_m = wide\n"), "radius_m");
    EXPECT_EQ(errorKey("[KFD]\nradius_min_neighbors = 0\n"), "radius_min_neighbors");
    EXPECT_EQ(errorKey("[KFD]\nradius_min_neighbors = 2.5\n"), "radius_min_neighbors");
    EXPECT_EQ(errorKey("[KFD]\nsor_k = 0\n"), "sor_k");
    EXPECT_EQ(errorKey("[KFD]\nsor_k = 1001\n"), "sor_k");
    EXPECT_EQ(errorKey("[KFD]\nsor_k = 3.5\n"), "sor_k");
    EXPECT_EQ(errorKey("[KFD]\nsor_std_mul = -0.1\n"), "sor_std_mul");
    EXPECT_EQ(errorKey("[KFD]\nsor_std_mul = 100.5\n"), "sor_std_mul");
    EXPECT_EQ(errorKey("[KFD]\npipeline = radius, sor, radius\n"),
              "<no error>");  // listed twice: two instances
    EXPECT_EQ(errorKey("[KFD]\npipeline = distance, pcl\n"), "pipeline");
    try {
        fromIniText("[KFD]\npipeline = distance, pcl\n");
        FAIL();
    } catch (const kfd::ConfigError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("radius"), std::string::npos) << what;
        EXPECT_NE(what.find("sor"), std::string::npos) << what;
    }

    // Listed with units in their help texts, and the pipeline key lists the new stages.
    std::size_t found = 0;
    for (const auto& k : kfd::configKeys()) {
        if (k.name == "radius_m" || k.name == "radius_min_neighbors" || k.name == "sor_k" ||
            k.name == "sor_std_mul") {
            ++found;
            EXPECT_NE(k.help.find('('), std::string::npos) << k.name << ": " << k.help;
        }
        if (k.name == "pipeline") {
            EXPECT_NE(k.range.find("radius"), std::string::npos) << k.range;
            EXPECT_NE(k.range.find("sor"), std::string::npos) << k.range;
        }
    }
    EXPECT_EQ(found, 4u);
}

TEST(Config, ConfigErrorIsAKfdErrorNamingTheKey) {
    try {
        fromIniText("[KFD]\nradius_min_neighbors = 0\n");
        FAIL();
    } catch (const kfd::Error& e) {  // the one exception root
        EXPECT_EQ(e.field(), "radius_min_neighbors");
        EXPECT_NE(dynamic_cast<const kfd::ConfigError*>(&e), nullptr);
    }
}

TEST(Config, BadViewSelectorKeysAreErrorsNamingTheKey) {
    for (const char* line :
         {"selector = histogram", "max_view_change = 0", "view_tolerance_deg = 90",
          "max_changed_fraction = 1.5", "degeneracy_ratio = -0.1", "corridor_interval_s = 0",
          "view_samples = 1"}) {
        SCOPED_TRACE(line);
        const std::string key = std::string(line).substr(0, std::string(line).find(' '));
        try {
            fromIniText(std::string("[KFD]\n") + line + "\n");
            ADD_FAILURE() << "accepted";
        } catch (const kfd::ConfigError& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
        }
    }
}

TEST(Config, BadKeyframeAlignmentKeysAreErrorsNamingTheKey) {
    // Issue 39's seventh step: the evidence denoiser's start from the tracker's poses.
    EXPECT_EQ(errorKey("[KFD]\ntrack_keyframe_start = sometimes\n"), "track_keyframe_start");
    EXPECT_EQ(errorKey("[KFD]\ntracked_refine_iterations = 4\n"), "tracked_refine_iterations");
    EXPECT_EQ(errorKey("[KFD]\ntracked_refine_iterations = 1.5\n"), "tracked_refine_iterations");
    EXPECT_EQ(errorKey("[KFD]\ntracked_refine_samples = 0\n"), "tracked_refine_samples");
    EXPECT_EQ(errorKey("[KFD]\ntracked_refine_samples = 129\n"), "tracked_refine_samples");
    EXPECT_EQ(errorKey("[KFD]\ntrack_keyframe_start = true\ntracked_refine_iterations = 0\n"
                       "tracked_refine_samples = 1\n"),
              "<no error>");
}

TEST(Config, KeyTableIsDerivedFromTheStageRegistry) {
    const auto& reg = kfd::defaultStageRegistry();
    std::vector<std::string> want{"pipeline", "selector", "variant"};  // then each key once
    for (const auto& s : reg.stages())
        for (const auto& k : s.keys)
            if (std::find(want.begin(), want.end(), k.name) == want.end()) want.push_back(k.name);
    std::vector<std::string> got;
    for (const auto& k : kfd::configKeys()) got.push_back(k.name);
    EXPECT_EQ(got, want);
    EXPECT_EQ(kfd::configKeys().front().range, reg.names());
    // toIni prints each listed stage's keys in its section, in the stage's order (the stage
    // list carries the choice keys).
    kfd::Pipeline::Params every;
    every.stages.clear();
    for (const auto& st : reg.stages()) every.stages.push_back(st.name);
    const std::string ini = kfd::toIni(every);
    EXPECT_EQ(ini.find("\nselector = "), std::string::npos);
    std::size_t pos = 0;
    for (const auto& st : reg.stages()) {
        pos = ini.find("\n[KFD." + st.name + "]\n", pos);
        ASSERT_NE(pos, std::string::npos) << st.name;
        for (const auto& k : st.keys) {
            const auto at = ini.find("\n" + k.name + " = ", pos);
            ASSERT_NE(at, std::string::npos) << k.name;
            pos = at + 1;
        }
    }
    // A registry with the core stages only has only the core keys.
    std::vector<std::string> core{"pipeline", "selector", "variant"};
    for (const auto& s : kfd::coreStageRegistry().stages())
        for (const auto& k : s.keys)
            if (std::find(core.begin(), core.end(), k.name) == core.end()) core.push_back(k.name);
    EXPECT_EQ(kfd::configKeys(kfd::coreStageRegistry()).size(), core.size());
}

// --list-keys's two defaults: the Params structs' (a C++ caller's) and kfd's (no configuration,
// and a key a configuration file leaves out: share/kfd/default.ini), read from the structs.
TEST(Config, EveryKeyCarriesItsParamsDefaultAndKfdsDefault) {
    std::map<std::string, kfd::ConfigKeyInfo> by_name;
    for (const auto& k : kfd::configKeys()) by_name[k.name] = k;
    const kfd::ViewKeyframeSelector::Params kf;
    const kfd::EvidenceFilter::Params ev;
    // window: 8 in the struct, and in kfd's defaults (issue 34: default.ini sets the keys of
    // the stages it lists; the paper rule's are the struct's).
    EXPECT_EQ(by_name["selector"].default_value, "view");
    EXPECT_EQ(by_name["variant"].kfd_value, "evidence");
    EXPECT_EQ(by_name["window"].default_value,
              std::to_string(kfd::KeyframeSelector::Params{}.window));
    EXPECT_EQ(by_name["window"].kfd_value,
              std::to_string(kfd::kfdDefaults().get<kfd::KeyframeStage>().window));
    EXPECT_EQ(by_name["window"].default_value, by_name["window"].kfd_value);
    // Keys default.ini leaves out: the struct's value in both.
    for (const auto& [key, value] : {std::pair{"incidence_deg", ev.incidence_deg},
                                     {"max_removed_fraction", ev.max_removed_fraction},
                                     {"view_tolerance_m", kf.view.tolerance_m}}) {
        EXPECT_EQ(by_name[key].default_value, kfd::keys::formatReal(value)) << key;
        EXPECT_EQ(by_name[key].kfd_value, kfd::keys::formatReal(value)) << key;
    }
    // Every key: its values are what toIni prints for each configuration.
    for (const auto& [params, field] :
         {std::pair{kfd::Pipeline::Params{}, &kfd::ConfigKeyInfo::default_value},
          {kfd::kfdDefaults(), &kfd::ConfigKeyInfo::kfd_value}}) {
        kfd::Pipeline::Params every = params;  // every stage listed: every key printed
        every.stages.clear();
        for (const auto& st : kfd::defaultStageRegistry().stages()) every.stages.push_back(st.name);
        const std::string ini = kfd::toIni(every);
        for (const auto& k : kfd::configKeys()) {
            if (k.name == "pipeline" || k.name == "selector" || k.name == "variant") continue;
            EXPECT_NE(ini.find("\n" + k.name + " = " + k.*field + "\n"), std::string::npos)
                << k.name;
        }
    }
    std::string stages;
    for (const auto& st : kfd::kfdDefaults().stages) stages += (stages.empty() ? "" : ",") + st;
    EXPECT_EQ(by_name["pipeline"].kfd_value, stages);
}

// selector and variant choose the stage of their role in the listed pipeline, wherever the
// file puts them; a value that names no stage is an error naming the key.
TEST(Config, ChoiceKeysReplaceTheStageOfTheirRole) {
    using V = std::vector<std::string>;
    EXPECT_EQ(fromIniText("[KFD]\nselector = paper\nvariant = reference\n").stages,
              (V{"odometry_check", "distance", "track", "keyframe", "denoise"}));
    EXPECT_EQ(
        fromIniText("[KFD]\nvariant = range_aware\npipeline = distance, evidence_denoise\n").stages,
        (V{"distance", "range_aware_denoise"}));
    EXPECT_EQ(fromIniText("[KFD]\npipeline = distance\nselector = paper\n").stages, V{"distance"});
    EXPECT_EQ(errorKey("[KFD]\nselector = histogram\n"), "selector");
}

TEST(Config, AFlatKeySetsItInEveryStageThatDeclaresIt) {
    const auto p = fromIniText("[KFD]\nangle_gap_factor = 30\nm_threshold = 7\n");
    EXPECT_EQ(p.get<kfd::DenoiseStage>().clustering.angle_gap_factor, 30.0);
    EXPECT_EQ(p.get<kfd::RangeAwareDenoiseStage>().clustering.angle_gap_factor, 30.0);
    EXPECT_EQ(p.get<kfd::DenoiseStage>().m_threshold, 7u);
    EXPECT_EQ(p.get<kfd::RangeAwareDenoiseStage>().filter.m_threshold, 7u);
    kfd::Pipeline::Params both = p;
    both.stages = {"denoise", "range_aware_denoise"};
    const std::string ini = kfd::toIni(both);
    EXPECT_NE(ini.find("[KFD.denoise]\n"), std::string::npos) << ini;
    EXPECT_NE(ini.find("angle_gap_factor = 30\n"), std::string::npos) << ini;
}

// Issue 9, item 4: duplicate keys, empty pipelines, YAML text checked before MRPT's parser.
namespace {

std::string yamlError(const std::string& text) {
    try {
        kfd::loadYamlText(text, "test");
    } catch (const kfd::ConfigError& e) {
        return e.what();
    }
    return "<no error>";
}

std::string yamlErrorKey(const std::string& text) {
    try {
        kfd::loadYamlText(text, "test");
    } catch (const kfd::ConfigError& e) {
        return e.key();
    }
    return "<no error>";
}

std::string writeFile(const kfd::test::TempDir& dir, const std::string& name,
                      const std::string& text) {
    const std::string path = dir / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

}  // namespace

std::string iniTextErrorKey(const std::string& text) {
    try {
        kfd::checkIniText(text);
    } catch (const kfd::ConfigError& e) {
        return e.key();
    }
    return "<no error>";
}

TEST(ConfigDuplicates, IniKeySetTwiceIsAnErrorNamingTheKey) {
    EXPECT_EQ(iniTextErrorKey("[KFD]\nwindow = 3\nbins = 20\nwindow = 4\n"), "window");
    EXPECT_EQ(iniTextErrorKey("[KFD]\nwindow = 3\n[kfd]\nWINDOW = 4\n"), "WINDOW");  // no case
    try {
        kfd::checkIniText("[KFD]\r\nwindow = 3\r\nwindow=4\r\n");
        FAIL();
    } catch (const kfd::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("lines 2 and 3"), std::string::npos) << e.what();
    }
    // The same key in another section, or commented out, is no duplicate.
    EXPECT_EQ(iniTextErrorKey("[ICP]\nwindow = 1\n[KFD]\nwindow = 3\n; window = 4\n# window = 5\n"),
              "<no error>");
    EXPECT_EQ(iniTextErrorKey("[ICP]\nwindow = 1\nwindow = 2\n"), "<no error>");
}

TEST(ConfigDuplicates, IniFileKeySetTwiceIsAnError) {
    kfd::test::TempDir dir("kfd_config_");
    const std::string path = writeFile(dir, "dup.ini", "[KFD]\nrings = 4\nrings = 5\n");
    try {
        kfd::loadConfigFile(path);
        FAIL();
    } catch (const kfd::ConfigError& e) {
        EXPECT_EQ(e.key(), "rings");
    }
    // loadIni on a CConfigFile (what kfd-icp-slam reads) checks the file's text too.
    mrpt::config::CConfigFile cfg(path);
    EXPECT_THROW(kfd::loadIni(cfg), kfd::ConfigError);
}

TEST(ConfigDuplicates, YamlKeySetTwiceIsAnErrorNamingTheKey) {
    EXPECT_EQ(yamlErrorKey("window: 3\nwindow: 4\n"), "window");
    EXPECT_EQ(yamlErrorKey("kfd:\n  bins: 10\n  rings: 3\n  bins: 12\n"), "bins");
    EXPECT_EQ(yamlErrorKey("kfd:\n  bins: 10\nkfd:\n  rings: 3\n"), "kfd");
    EXPECT_EQ(yamlErrorKey("kfd:\n  bins: 10\n  rings: 3\n"), "<no error>");
}

TEST(ConfigEmptyPipeline, IsAnErrorNamingPipeline) {
    EXPECT_EQ(errorKey("[KFD]\npipeline =\n"), "pipeline");
    EXPECT_EQ(errorKey("[KFD]\npipeline = , ,\n"), "pipeline");
    EXPECT_EQ(yamlErrorKey("pipeline: []\n"), "pipeline");
    EXPECT_EQ(yamlErrorKey("pipeline: ''\n"), "pipeline");
    kfd::Pipeline::Params p;
    EXPECT_THROW(kfd::applyConfigKey(p, "pipeline", "  ", kfd::defaultStageRegistry()),
                 kfd::ConfigError);
    EXPECT_EQ(errorKey("[KFD]\npipeline = denoise\n"), "<no error>");
}

TEST(ConfigYamlCheck, TheFourByteFileThatHungLibfyamlIsAnError) {
    // "%\xff\xff\n": a directive with bytes that are not UTF-8 made libfyaml (under MRPT's
    // YAML parser) loop forever; kfd-filter -c hung. It must be a ConfigError, quickly.
    const std::string path = std::string(KFD_SOURCE_DIR) + "/test/data/yaml-hang-4byte.yaml";
    ASSERT_EQ(kfd::test::fileBytes(path), std::string("%\xff\xff\n"));
    try {
        kfd::loadConfigFile(path);
        FAIL();
    } catch (const kfd::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("not UTF-8"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("yaml-hang-4byte.yaml"), std::string::npos);
    }
    // The same directive in plain ASCII is refused by the subset rule.
    EXPECT_NE(yamlError("%YAML 1.2\n").find("'%' is not supported"), std::string::npos);
}

TEST(ConfigYamlCheck, SizeLimit) {
    std::string big = "window: 3\n";
    big += std::string(kfd::kMaxConfigBytes, '#');
    EXPECT_NE(yamlError(big).find("larger than"), std::string::npos);
    kfd::test::TempDir dir("kfd_config_");
    EXPECT_THROW(kfd::loadConfigFile(writeFile(dir, "big.yaml", big)), kfd::ConfigError);
    // Just under the limit (a long comment) is read.
    std::string ok = "window: 3\n#";
    ok += std::string(kfd::kMaxConfigBytes - ok.size(), 'x');
    EXPECT_EQ(kfd::loadYamlText(ok).get<kfd::KeyframeStage>().window, 3u);
}

TEST(ConfigYamlCheck, Encoding) {
    EXPECT_NE(yamlError("window: 3 # \xff\n").find("not UTF-8"), std::string::npos);
    EXPECT_NE(yamlError("window: 3 # \xc3\n").find("not UTF-8"), std::string::npos);  // cut
    EXPECT_NE(yamlError("window: 3 # \xc0\xaf\n").find("not UTF-8"), std::string::npos);
    EXPECT_NE(yamlError("window: 3 # \xe0\x80\xaf\n").find("overlong"), std::string::npos);
    EXPECT_NE(yamlError("window: 3 # \xed\xa0\x80\n").find("invalid"), std::string::npos);
    EXPECT_NE(yamlError("window: 3 # \xf4\x90\x80\x80\n").find("invalid"), std::string::npos);
    // A byte-order mark is fine as the first character only.
    EXPECT_EQ(yamlError("\xef\xbb\xbfwindow: 3\n"), "<no error>");
    EXPECT_NE(yamlError("window: 3\n\xef\xbb\xbf").find("byte-order mark"), std::string::npos);
    // Valid multi-byte UTF-8 in a comment is fine; the error names the line.
    EXPECT_EQ(yamlError("# fen\xc3\xaatre \xe2\x82\xac \xf0\x9f\x98\x80\nwindow: 3\n"),
              "<no error>");
    EXPECT_NE(yamlError("window: 3\nbins: 4 # \xff\n").find("line 2"), std::string::npos);
}

TEST(ConfigYamlCheck, ControlCharacters) {
    EXPECT_NE(yamlError(std::string("window: 3\0\n", 11)).find("control character 0"),
              std::string::npos);
    EXPECT_NE(yamlError("window: 3\x07\n").find("control character 7"), std::string::npos);
    EXPECT_NE(yamlError("window: 3\x7f\n").find("control character"), std::string::npos);
    EXPECT_NE(yamlError("window: 3 # \xc2\x85\n").find("control character"), std::string::npos);
    // Tab (not in indentation), CR and LF are fine.
    EXPECT_EQ(yamlError("window:\t3\r\nbins: 4\r\n"), "<no error>");
}

TEST(ConfigYamlCheck, SubsetRules) {
    const char* refused[][2] = {
        {"{window: 3}\n", "'{'"},
        {"kfd: {window: 3}\n", "'{'"},
        {"window: &a 3\n", "'&'"},
        {"window: *a\n", "'*'"},
        {"window: !!int 3\n", "'!'"},
        {"%TAG ! tag:x\nwindow: 3\n", "'%'"},
        {"? window\n: 3\n", "'?'"},
        {"variant: |\n  range_aware\n", "'|'"},
        {"variant: >\n  range_aware\n", "'>'"},
        {"window: 3\n---\nwindow: 4\n", "document markers"},
        {"window: 3\n...\n", "document markers"},
        {"pipeline: [[distance]]\n", "nested list"},
        {"pipeline: [distance\n", "unterminated list"},
        {"pipeline: distance]\n", "unbalanced"},
        {"kfd:\n\twindow: 3\n", "tab in indentation"},
        {"variant: 'range_aware\n", "unterminated quote"},
        {"kfd:\n  a:\n    b:\n      window: 3\n", "more than 3 levels"},
        {"  window: 3\n", "indented key without a map"},
    };
    for (const auto& r : refused) {
        const std::string msg = yamlError(r[0]);
        EXPECT_NE(msg.find(r[1]), std::string::npos) << r[0] << " -> " << msg;
    }
    // What kfd's keys need is accepted: comments with any character, quoted values with '#',
    // flow and block lists, the kfd: map.
    EXPECT_EQ(yamlError("# {}&*!%?|>@` ---\nwindow: 3 # {&*}\nvariant: 'range_aware'\n"),
              "<no error>");
    EXPECT_EQ(yamlError("kfd:\n  pipeline:\n    - distance\n    - denoise\n  rings: 4\n"),
              "<no error>");
    EXPECT_EQ(yamlError("pipeline: [distance, keyframe]\nwindow: \"3\"\n"), "<no error>");
}

// Issue 38's low items: what MRPT's readers took silently or reported without its cause.
TEST(ConfigBadInput, HexNumbersNulBytesUndefinedVariablesAndKeysBesideKfdAreRefused) {
    // strtod read "0x10" as 16.
    EXPECT_EQ(errorKey("[KFD]\n[KFD.view_keyframe]\nmax_consecutive_drops = 0x10\n"),
              "max_consecutive_drops");
    EXPECT_EQ(errorKey("[KFD]\n[KFD.view_keyframe]\nmax_view_change = 0x1p-1\n"),
              "max_view_change");
    EXPECT_EQ(errorKey("[KFD]\n[KFD.view_keyframe]\nmax_consecutive_drops = 16\n"), "<no error>");
    kfd::test::TempDir dir("kfd_config_");
    // The C string ended at the NUL: "3<NUL>junk" was 3.
    const std::string nul = writeFile(
        dir, "nul.ini",
        std::string("[KFD]\n[KFD.view_keyframe]\nmax_consecutive_drops = 3") + '\0' + "junk\n");
    const std::string nul_yaml =
        writeFile(dir, "nul.yaml",
                  std::string("view_keyframe:\n  max_consecutive_drops: 3") + '\0' + "junk\n");
    for (const std::string& path : {nul, nul_yaml}) {
        try {
            kfd::loadConfigFile(path);
            ADD_FAILURE() << path << " accepted";
        } catch (const kfd::ConfigError& e) {
            EXPECT_NE(std::string(e.what()).find(" holds a NUL byte: not a text file"),
                      std::string::npos)
                << e.what();
        }
    }
    // "==== MRPT exception ====" lost the cause.
    const std::string undefined = writeFile(
        dir, "var.ini", "[KFD]\n[KFD.view_keyframe]\nmax_consecutive_drops = ${KFD_NOPE}\n");
    try {
        kfd::loadConfigFile(undefined);
        ADD_FAILURE() << "an undefined ${VAR} accepted";
    } catch (const kfd::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("var.ini line 3: ${KFD_NOPE} is not defined"),
                  std::string::npos)
            << e.what();
    }
    const std::string defined = writeFile(
        dir, "def.ini",
        "@define DROPS 7\n[KFD]\n[KFD.view_keyframe]\nmax_consecutive_drops = ${DROPS}\n");
    EXPECT_NE(kfd::toIni(kfd::loadConfigFile(defined)).find("max_consecutive_drops = 7"),
              std::string::npos);
    // A key beside the kfd: map was silently ignored.
    EXPECT_EQ(yamlErrorKey("kfd:\n  view_keyframe:\n    max_consecutive_drops: 3\n"
                           "view_keyframe:\n  max_consecutive_drops: 5\n"),
              "view_keyframe");
}

TEST(ConfigFuzzFindings, MalformedMrptExpansionIsAConfigError) {
    // fuzz_ini: MRPT's CConfigFile throws its own exception for an unclosed $eval{ (and the
    // other expansions); it reached the tools as a non-kfd exception.
    kfd::test::TempDir dir("kfd_config_");
    const std::string path = writeFile(dir, "eval.ini", "[KFD]\nm_threshold = $eval{3\n");
    try {
        kfd::loadConfigFile(path);
        FAIL();
    } catch (const kfd::ConfigError& e) {
        EXPECT_NE(std::string(e.what()).find("eval.ini"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot read .ini file"), std::string::npos)
            << e.what();
    }
}
