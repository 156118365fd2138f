// kfd-icp-slam end to end: equality with MRPT's icp-slam, pose error on a real log, every mode.
#include <gtest/gtest.h>
#include <mrpt/img/CImage.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPlanarLaserScan.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "kfd/baselines/decimate_stage.h"
#include "kfd/eval/trajectory.h"
#include "kfd/io/rawlog_filter.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/default_stages.h"
#include "kfd/os/cancel.h"
#include "kfd/pipeline/format.h"
#include "kfd/report/slam_report.h"
#include "kfd/sim/simulator.h"
#include "kfd/slam/icp_slam_runner.h"
#include "kfd/stages/keyframe_stage.h"
#include "test_files.h"

namespace fs = std::filesystem;

namespace {

const std::string kSena =
    std::string(KFD_MRPT_DATASETS_DIR) + "/2006-01ENE-21-SENA_Telecom Faculty_one_loop_only.rawlog";
const std::string kMitCsail = std::string(KFD_DATASETS_DIR) + "/mit-csail/mit-csail.rawlog";
const std::string kMitCsailRel = std::string(KFD_DATASETS_DIR) + "/mit-csail/mit-csail.relations";
const std::string kConfig = std::string(KFD_SOURCE_DIR) + "/share/kfd-icp-slam/sick-180-5hz.ini";

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_slam_") {}
};

std::string text(const std::string& path) { return kfd::test::fileBytes(path); }

std::size_t lines(const std::string& path) {
    std::ifstream f(path);
    std::size_t n = 0;
    std::string l;
    while (std::getline(f, l)) ++n;
    return n;
}

// A CSV file's rows, split at commas (a trailing comma: an empty last field), header included.
std::vector<std::vector<std::string>> csvRows(const std::string& path) {
    std::vector<std::vector<std::string>> out;
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        std::vector<std::string> fields;
        std::stringstream ss(line);
        std::string field;
        while (std::getline(ss, field, ',')) fields.push_back(field);
        if (!line.empty() && line.back() == ',') fields.emplace_back();
        out.push_back(fields);
    }
    return out;
}

// kConfig with keys of its [`section`] set, written to `path`: each "KEY = VALUE" replaces
// the key's line in that section, or is added at the section's top when it has none.
std::string configWith(const std::string& path, const std::string& section,
                       const std::vector<std::pair<std::string, std::string>>& keys) {
    std::string ini = text(kConfig);
    const std::string header = "[" + section + "]\n";
    const auto begin = ini.find(header);
    if (begin == std::string::npos) {
        ADD_FAILURE() << "no " << header << " in " << kConfig;
        return path;
    }
    for (const auto& [key, value] : keys) {
        const std::string line = key + " = " + value + "\n";
        const auto end = std::min(ini.find("\n[", begin), ini.size());
        const auto at = ini.find("\n" + key + " ", begin);
        if (at == std::string::npos || at >= end)
            ini.insert(begin + header.size(), line);
        else
            ini.replace(at + 1, ini.find('\n', at + 1) - at, line);
    }
    std::ofstream(path) << ini;
    return path;
}

// A run and its report, as kfd-icp-slam does.
kfd::IcpSlamSummary runAndReport(const kfd::IcpSlamOptions& o) {
    const auto result = kfd::IcpSlamRunner().run(o);
    kfd::writeIcpSlamReport(result);
    return result.summary;
}

kfd::IcpSlamOptions options(const std::string& rawlog, const std::string& out,
                            kfd::PrefilterMode mode) {
    kfd::IcpSlamOptions o;
    o.config_file = kConfig;
    o.rawlog = rawlog;
    o.output_dir = out;
    o.mode = mode;
    return o;
}

}  // namespace

TEST(IcpSlamRunner, ModeNoneMatchesMrptIcpSlam) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    if (std::system("command -v icp-slam > /dev/null") != 0)
        GTEST_SKIP() << "MRPT's icp-slam not installed (mrpt-apps)";
    TempDir dir;
    // icp-slam writes into logOutput_dir; give it a config copy that points there.
    std::string cfg = text(kConfig);
    const auto pos = cfg.find("\nlogOutput_dir");
    ASSERT_NE(pos, std::string::npos);
    cfg.replace(pos + 1, cfg.find('\n', pos + 1) - pos - 1, "logOutput_dir=" + (dir / "mrpt"));
    std::ofstream(dir / "icp.ini") << cfg;
    const std::string cmd =
        "icp-slam '" + (dir / "icp.ini") + "' '" + kSena + "' > '" + (dir / "icp.log") + "' 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << text(dir / "icp.log");

    const auto s = runAndReport(options(kSena, dir / "kfd", kfd::PrefilterMode::None));
    EXPECT_EQ(s.scans_kept, s.scans_in);
    const std::string mine = text(dir / "kfd/log_estimated_path.txt");
    const std::string theirs = text(dir / "mrpt/log_estimated_path.txt");
    EXPECT_GT(lines(dir / "kfd/log_estimated_path.txt"), 200u);
    EXPECT_EQ(mine, theirs);
}

TEST(IcpSlamRunner, KfdOnMitCsailHasBoundedErrorAndAPoseForEveryScan) {
    if (!fs::exists(kMitCsail)) GTEST_SKIP() << "dataset missing: " << kMitCsail;
    TempDir dir;
    auto o = options(kMitCsail, dir / "out", kfd::PrefilterMode::Kfd);
    o.relations = kMitCsailRel;
    const auto s = runAndReport(o);
    EXPECT_EQ(s.scans_in, 1988u);
    EXPECT_GT(s.dropped_pct, 5.0);
    ASSERT_TRUE(s.relations.has_value());
    EXPECT_EQ(s.relations->unmatched, 0u);  // every relation stamp found a pose
    EXPECT_EQ(s.relations->used, 1172u);
    // Bounds above every measured run and far below a failed one (lost tracking gives tens of
    // metres and degrees). One run is not a measurement: over 20 perturbed runs each of
    // none / keyframe / kfd (sick-180-5hz.ini, kfd-compare) the means ranged 0.09-3.0 m and
    // 1.4-9.0 deg, so a tighter bound would fail on chaos, not on a fault.
    EXPECT_LT(s.relations->trans_mean, 3.5);
    EXPECT_LT(s.relations->rot_mean_deg, 10.0);
    const auto traj = kfd::readTum(dir / "out/trajectory.tum");
    EXPECT_EQ(traj.size(), s.scans_in);
    EXPECT_EQ(lines(dir / "out/scans.csv"), s.scans_in + 1);
    for (const char* f : {"summary.json", "final_map.simplemap", "map.png", "map_figure.png",
                          "report.md", "log_estimated_path.txt"})
        EXPECT_TRUE(fs::exists(dir / (std::string("out/") + f))) << f;
    const std::string json = text(dir / "out/summary.json");
    for (const char* key : {"\"scans_in\"", "\"scans_kept\"", "\"dropped_pct\"",
                            "\"points_removed\"", "\"prefilter_us_per_scan\"",
                            "\"icp_ms_per_scan\"", "\"cpu_s_total\"", "\"trans_mean_m\""})
        EXPECT_NE(json.find(key), std::string::npos) << key;
}

// kfd-icp-slam's scans.csv and kfd-filter's stats file are one writer's: the same columns,
// the door's records, kfd-icp-slam adding the pose; both summaries come from the same counters.
TEST(IcpSlamRunner, ScansCsvIsTheDoorsRecordWithThePose) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    const auto s = runAndReport(options(kSena, dir / "slam", kfd::PrefilterMode::Kfd));
    kfd::RawlogFilterOptions fo;
    fo.input = kSena;
    fo.output = dir / "out.rawlog";
    fo.stats_csv = dir / "stats.csv";
    fo.pipeline = kfd::kfdDefaults();
    const auto f = kfd::RawlogFilter().run(fo);
    const auto slam = csvRows(dir / "slam/scans.csv"), filter = csvRows(dir / "stats.csv");
    ASSERT_FALSE(slam.empty());
    ASSERT_FALSE(filter.empty());
    EXPECT_EQ(slam[0], filter[0]);  // one column set
    // Columns by name: the door's, the listed stages' declared ones, ICP's and the poses'.
    const auto col = [&](const std::string& name) {
        const auto it = std::find(slam[0].begin(), slam[0].end(), name);
        EXPECT_NE(it, slam[0].end()) << name;
        return static_cast<std::size_t>(it - slam[0].begin());
    };
    const std::size_t n = slam[0].size(), kept_col = col("kept"), goodness = col("icp_goodness"),
                      x = col("x");
    EXPECT_EQ(kept_col, 3u);
    EXPECT_EQ(col("odometry_check"), 10u);  // the first stage's first column
    EXPECT_EQ(x, n - 3);
    std::size_t kept = 0, corrected = 0, rejected = 0;
    for (std::size_t i = 1; i < slam.size(); ++i) {
        ASSERT_EQ(slam[i].size(), n) << i;
        kept += slam[i][kept_col] == "1";
        EXPECT_FALSE(slam[i][x].empty()) << i;  // the SLAM pose
        const std::string& g = slam[i][goodness];
        if (g.empty()) continue;
        EXPECT_EQ(slam[i][kept_col], "1") << i;  // only kept scans reach ICP
        ++corrected;
        rejected += g.back() == 'r';
        const double v = std::stod(g);
        EXPECT_GE(v, 0.0) << i;
        EXPECT_LE(v, 1.05) << i;  // MRPT's share of matched points can pass 1 by a little
    }
    EXPECT_EQ(kept, s.scans_kept);
    EXPECT_EQ(slam.size(), s.scans_in + 1);
    // ICP's goodness of every correction, from the map builder's log (a re-match runs the
    // rejected scan's ICP once more: its row keeps the last verdict).
    EXPECT_GT(corrected, 10u);
    EXPECT_LE(corrected, s.icp_runs);
    EXPECT_LE(s.icp_runs, corrected + s.rematches);
    EXPECT_LE(rejected, s.icp_rejected);
    EXPECT_LE(s.icp_rejected, rejected + s.rematches);
    EXPECT_GT(s.icp_goodness_median, 0.4);
    EXPECT_LE(s.icp_goodness_median, 1.05);
    for (std::size_t i = 1; i < filter.size(); ++i) {
        ASSERT_EQ(filter[i].size(), n) << i;
        EXPECT_TRUE(filter[i][x].empty()) << i;         // kfd-filter has no SLAM pose
        EXPECT_TRUE(filter[i][goodness].empty()) << i;  // nor ICP
    }
    EXPECT_EQ(filter.size(), f.scans_in + 1);
    // The same counters: the scans both drivers gave the door add up alike.
    EXPECT_EQ(s.scans_kept + s.scans_dropped + s.scans_skipped, s.scans_in);
    EXPECT_EQ(f.scans_kept + f.scans_dropped + f.scans_skipped, f.scans_in);
    EXPECT_EQ(s.points_removed, s.stageTotal("points_removed_range") + s.points_removed_noise);
}

TEST(IcpSlamRunner, EveryModeRunsAndAccountsForEveryScan) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    for (auto mode :
         {kfd::PrefilterMode::None, kfd::PrefilterMode::Odometry, kfd::PrefilterMode::Keyframe,
          kfd::PrefilterMode::Kfd, kfd::PrefilterMode::Dbscan}) {
        SCOPED_TRACE(kfd::toString(mode));
        auto o = options(kSena, dir / kfd::toString(mode), mode);
        o.write_map = false;
        const auto s = runAndReport(o);
        // MRPT's action/frame reader (as in icp-slam, which also logs 224 poses) yields 224 of
        // the file's 225 scans.
        EXPECT_EQ(s.scans_in, 224u);
        EXPECT_EQ(kfd::readTum(dir / (std::string(kfd::toString(mode)) + "/trajectory.tum")).size(),
                  224u);
        const bool drops = mode == kfd::PrefilterMode::Odometry ||
                           mode == kfd::PrefilterMode::Keyframe || mode == kfd::PrefilterMode::Kfd;
        if (drops) {
            EXPECT_LT(s.scans_kept, s.scans_in);
        } else {
            EXPECT_EQ(s.scans_kept, s.scans_in);
        }
        const bool denoises = mode == kfd::PrefilterMode::Kfd || mode == kfd::PrefilterMode::Dbscan;
        if (denoises) {
            EXPECT_GT(s.points_removed, 0u);
        }
        if (mode == kfd::PrefilterMode::None) {
            EXPECT_EQ(s.points_removed, 0u);
        }
    }
}

// kfd-filter reads SENA's 225 scans, icp-slam's steps 224: the one in the first sensory frame
// (no odometry action before it) is counted apart, and so are the scans before rawlog_offset,
// so that both apps account for the same scans (issue 23).
TEST(IcpSlamRunner, ScansOutsideIcpSlamsStepsAreCountedApart) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    kfd::RawlogFilterOptions f;
    f.input = kSena;
    f.output = dir / "filtered.rawlog";
    f.pipeline = kfd::kfdDefaults();
    const auto filtered = kfd::RawlogFilter().run(f);
    auto o = options(kSena, dir / "all", kfd::PrefilterMode::None);
    o.write_map = false;
    const auto all = runAndReport(o);
    EXPECT_EQ(all.scans_without_step, 1u);
    EXPECT_EQ(all.scans_before_offset, 0u);
    EXPECT_EQ(all.scans_in + all.scans_without_step, filtered.scans_in);
    EXPECT_NE(text(dir / "all/summary.json").find("\"scans_without_step\": 1"), std::string::npos);
    // rawlog_offset = 20 objects: the scans before it are counted apart too.
    std::string cfg = text(kConfig);
    const auto pos = cfg.find("\nrawlog_offset");
    ASSERT_NE(pos, std::string::npos);
    cfg.replace(pos + 1, cfg.find('\n', pos + 1) - pos - 1, "rawlog_offset = 20");
    std::ofstream(dir / "offset.ini") << cfg;
    o.config_file = dir / "offset.ini";
    o.output_dir = dir / "offset";
    const auto later = runAndReport(o);
    EXPECT_GT(later.scans_before_offset, 0u);
    EXPECT_EQ(later.scans_in + later.scans_before_offset + later.scans_without_step,
              filtered.scans_in);
    // kfd-icp-slam's summary says so under its scan counts.
    const std::string cmd = "'" + std::string(KFD_ICP_SLAM_EXE) + "' '" + (dir / "offset.ini") +
                            "' '" + kSena + "' -o '" + (dir / "app") + "' -m none --no-map -q > '" +
                            (dir / "app.txt") + "' 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << text(dir / "app.txt");
    const std::string want =
        "not in: 1 scan in a sensory frame without an odometry action (MRPT's icp-slam reads no "
        "step from it), " +
        kfd::plural(later.scans_before_offset, "scan") + " before rawlog_offset";
    EXPECT_NE(text(dir / "app.txt").find(want), std::string::npos) << text(dir / "app.txt");
}

TEST(IcpSlamRunner, OdometryModeMatchesATargetDropRate) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    for (double target : {20.0, 50.0}) {
        auto o = options(kSena, dir / "odo", kfd::PrefilterMode::Odometry);
        o.write_map = false;
        o.odometry_target_drop_pct = target;
        const auto s = runAndReport(o);
        EXPECT_NEAR(s.dropped_pct, target, 3.0);  // 225 scans: steps of 0.44 %
        EXPECT_GT(s.pipeline.get<kfd::MotionStage>().max_distance_m, 0.0);
    }
}

// kfd-compare's repeats: skip the first K scans; the same log, K scans fewer, no pose for them.
TEST(IcpSlamRunner, SkipScansStartsTheRunKScansLater) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    auto o = options(kSena, dir / "k0", kfd::PrefilterMode::None);
    o.write_map = false;
    const auto all = runAndReport(o);
    o.output_dir = dir / "k3";
    o.skip_scans = 3;
    const auto later = runAndReport(o);
    EXPECT_EQ(later.scans_skipped_start, 3u);
    EXPECT_EQ(later.scans_in, all.scans_in - 3);
    const auto a = kfd::readTum(dir / "k0/trajectory.tum");
    const auto b = kfd::readTum(dir / "k3/trajectory.tum");
    ASSERT_EQ(b.size(), a.size() - 3);
    EXPECT_EQ(b.front().t, a[3].t);  // the first pose is the fourth scan's
    EXPECT_NE(text(dir / "k0/summary.json").find("\"scans_skipped_start\": 0"), std::string::npos);
}

// Laser-only: neither the pre-filter nor the map builder sees odometry. The motion stage then
// keeps every scan (nothing to measure), and the estimate differs from a run with odometry.
TEST(IcpSlamRunner, LaserOnlyGivesNoOdometryToThePrefilterOrToIcp) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    auto o = options(kSena, dir / "odo", kfd::PrefilterMode::Odometry);
    o.write_map = false;
    const auto with = runAndReport(o);
    EXPECT_LT(with.scans_kept, with.scans_in);
    o.output_dir = dir / "lo";
    o.laser_only = true;
    const auto without = runAndReport(o);
    EXPECT_TRUE(without.laser_only);
    EXPECT_EQ(without.scans_kept, without.scans_in);
    auto none = options(kSena, dir / "none", kfd::PrefilterMode::None);
    none.write_map = false;
    runAndReport(none);
    none.output_dir = dir / "none-lo";
    none.laser_only = true;
    runAndReport(none);
    EXPECT_NE(text(dir / "none/trajectory.tum"), text(dir / "none-lo/trajectory.tum"));
}

// Decimation keeps a fixed share evenly; matched to another mode, it drops what that mode drops
// on the same run (a pre-pass of the pre-filter alone), and so does the odometry baseline.
TEST(IcpSlamRunner, DecimateAndOdometryMatchTheDropRateOfAnotherMode) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    auto k = options(kSena, dir / "kfd", kfd::PrefilterMode::Kfd);
    k.write_map = false;
    k.skip_scans = 2;
    const auto kfd_run = runAndReport(k);
    ASSERT_GT(kfd_run.dropped_pct, 5.0);
    for (auto mode : {kfd::PrefilterMode::Decimate, kfd::PrefilterMode::Odometry}) {
        SCOPED_TRACE(kfd::toString(mode));
        auto o = options(kSena, dir / kfd::toString(mode), mode);
        o.write_map = false;
        o.skip_scans = 2;
        o.match_drop_of = kfd::PrefilterMode::Kfd;
        const auto s = runAndReport(o);
        ASSERT_TRUE(s.target_drop_pct.has_value());
        EXPECT_DOUBLE_EQ(*s.target_drop_pct, kfd_run.dropped_pct);
        EXPECT_NEAR(s.dropped_pct, kfd_run.dropped_pct, 1.0);  // 222 scans: 0.45 % a scan
        EXPECT_GE(s.cpu_s_match, 0.0);
    }
    auto d = options(kSena, dir / "dec", kfd::PrefilterMode::Decimate);
    d.write_map = false;
    d.odometry_target_drop_pct = 75.0;
    const auto s = runAndReport(d);
    EXPECT_EQ(s.scans_kept, 56u);  // every 4th of 224
    EXPECT_DOUBLE_EQ(s.pipeline.get<kfd::DecimateStage>().keep_fraction, 0.25);
    // Matching needs a mode that can match, and one target only.
    auto bad = options(kSena, dir / "bad", kfd::PrefilterMode::Kfd);
    bad.match_drop_of = kfd::PrefilterMode::Keyframe;
    EXPECT_THROW(runAndReport(bad), kfd::SlamError);
    bad.mode = kfd::PrefilterMode::Decimate;
    bad.odometry_target_drop_pct = 10.0;
    EXPECT_THROW(runAndReport(bad), kfd::SlamError);
}

// Relations over at most split_seconds are local, the others long; both are in the summary.
TEST(IcpSlamRunner, RelationsAreSplitIntoLocalAndLong) {
    if (!fs::exists(kMitCsail)) GTEST_SKIP() << "dataset missing: " << kMitCsail;
    TempDir dir;
    auto o = options(kMitCsail, dir / "out", kfd::PrefilterMode::None);
    o.write_map = false;
    o.relations = kMitCsailRel;
    const auto s = runAndReport(o);
    ASSERT_TRUE(s.relations_local && s.relations_long);
    EXPECT_EQ(s.relations_local_count + s.relations_long_count, 1172u);
    EXPECT_EQ(s.relations_local->used + s.relations_long->used, s.relations->used);
    EXPECT_GT(s.relations_local_count, s.relations_long_count);
    // Long relations carry the drift: their mean error is the larger.
    EXPECT_GT(s.relations_long->trans_mean, s.relations_local->trans_mean);
    const std::string json = text(dir / "out/summary.json");
    for (const char* key : {"\"split_seconds\": 10", "\"relations_local\"", "\"relations_long\""})
        EXPECT_NE(json.find(key), std::string::npos) << key;
    o.split_seconds = -1.0;
    EXPECT_THROW(runAndReport(o), kfd::SlamError);
}

TEST(IcpSlamRunner, BadInputIsAClearError) {
    TempDir dir;
    auto o = options(dir / "missing.rawlog", dir / "out", kfd::PrefilterMode::Kfd);
    EXPECT_THROW(runAndReport(o), kfd::SlamError);
    o.config_file = dir / "missing.ini";
    EXPECT_THROW(runAndReport(o), kfd::SlamError);
    std::ofstream(dir / "text.rawlog") << "not a rawlog\n";
    o = options(dir / "text.rawlog", dir / "out", kfd::PrefilterMode::Kfd);
    EXPECT_THROW(runAndReport(o), kfd::SlamError);
    std::ofstream(dir / "bad.ini") << text(kConfig) << "\n[KFD]\nwindw = 2\n";
    o = options(kSena, dir / "out", kfd::PrefilterMode::Kfd);
    o.config_file = dir / "bad.ini";
    EXPECT_THROW(runAndReport(o), kfd::ConfigError);
    // Issue 38: MRPT's readers took "1.5" as 1 and "abc" as false, silently.
    for (const auto& [key, value] : {std::pair<std::string, std::string>{"LOG_FREQUENCY", "1.5"},
                                     {"SAVE_3D_SCENE", "abc"},
                                     {"SAVE_POSE_LOG", "2"}}) {
        o.config_file = configWith(dir / "strict.ini", "MappingApplication", {{key, value}});
        try {
            runAndReport(o);
            ADD_FAILURE() << key << " = " << value << " accepted";
        } catch (const kfd::ConfigError& e) {
            EXPECT_EQ(e.key(), key);
            EXPECT_NE(std::string(e.what()).find("'" + value + "'"), std::string::npos) << e.what();
        }
    }
}

namespace {

// scans.csv's column `name`, one entry per scan.
std::vector<std::string> csvColumn(const std::vector<std::vector<std::string>>& rows,
                                   const std::string& name) {
    std::vector<std::string> out;
    if (rows.empty()) return out;
    const auto col = std::find(rows[0].begin(), rows[0].end(), name) - rows[0].begin();
    if (static_cast<std::size_t>(col) == rows[0].size()) {
        ADD_FAILURE() << "no column " << name;
        return out;
    }
    for (std::size_t i = 1; i < rows.size(); ++i)
        out.push_back(static_cast<std::size_t>(col) < rows[i].size() ? rows[i][col] : "?");
    return out;
}

// The pre-filter's own decision per scan (scans.csv): kept, and not a dropped scan that went to
// ICP for a recovery or a re-match (those depend on ICP, which the denoise removals change).
std::vector<bool> doorKept(const std::vector<std::vector<std::string>>& rows) {
    const auto kept = csvColumn(rows, "kept"), reason = csvColumn(rows, "reason");
    std::vector<bool> out;
    for (std::size_t i = 0; i < kept.size(); ++i)
        out.push_back(kept[i] == "1" && reason[i].rfind("icp_", 0) != 0);
    return out;
}

const std::string kOffice = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";

// kfd mode on `log` with the configuration `off` into dir/off, then `on` into dir/on.
std::pair<kfd::IcpSlamSummary, kfd::IcpSlamSummary> runOffOn(const std::string& log,
                                                             const TempDir& dir,
                                                             const std::string& off,
                                                             const std::string& on) {
    auto o = options(log, dir / "off", kfd::PrefilterMode::Kfd);
    o.config_file = off;
    o.write_map = false;
    auto a = runAndReport(o);
    o.output_dir = dir / "on";
    o.config_file = on;
    return {std::move(a), runAndReport(o)};
}

}  // namespace

// next_scan (issue 25) holds each keyframe until the sensor's next scan: kfd-icp-slam's step
// waits for it and runs ICP one step later. The pre-filter's decisions do not depend on it,
// every scan still gets one pose and one row, and the counters count every pending scan once
// finished. On the observations layout (the bundled log) and the actions-and-frames one.
TEST(IcpSlamRunner, NextScanKeepsTheSameScansWithOnePoseAndRowPerScan) {
    TempDir dir;
    const std::string off =
        configWith(dir / "off.ini", "KFD.evidence_denoise", {{"next_scan", "false"}});
    const std::string on =
        configWith(dir / "on.ini", "KFD.evidence_denoise", {{"next_scan", "true"}});
    std::vector<std::string> logs = {kOffice};
    if (fs::exists(kSena)) logs.push_back(kSena);
    for (const std::string& log : logs) {
        SCOPED_TRACE(log);
        const auto [a, b] = runOffOn(log, dir, off, on);
        const auto rows_a = csvRows(dir / "off/scans.csv"), rows_b = csvRows(dir / "on/scans.csv");
        ASSERT_EQ(b.scans_in, a.scans_in);
        EXPECT_GT(b.scans_in, 100u);
        EXPECT_EQ(b.scans_skipped, a.scans_skipped);
        EXPECT_EQ(b.scans_kept - b.scans_kept_for_recovery - b.scans_rematched,
                  a.scans_kept - a.scans_kept_for_recovery - a.scans_rematched);
        EXPECT_LT(b.scans_kept, b.scans_in);  // the keyframe stage dropped some
        EXPECT_EQ(doorKept(rows_b), doorKept(rows_a));
        EXPECT_EQ(csvColumn(rows_b, "index"), csvColumn(rows_a, "index"));
        EXPECT_EQ(csvColumn(rows_b, "timestamp"), csvColumn(rows_a, "timestamp"));
        EXPECT_EQ(kfd::readTum(dir / "on/trajectory.tum").size(), b.scans_in);
        EXPECT_EQ(b.entries, a.entries);  // every step ran, the waiting ones too
        EXPECT_EQ(lines(dir / "on/log_estimated_path.txt"),
                  lines(dir / "off/log_estimated_path.txt"));
        // The summary and the rows agree: each pending scan counted and recorded once, final.
        const auto kept = csvColumn(rows_b, "kept"), removed = csvColumn(rows_b, "removed_noise");
        const auto door = doorKept(rows_b);
        ASSERT_EQ(kept.size(), b.scans_in);
        std::size_t kept_rows = 0, removed_noise = 0;
        for (std::size_t i = 0; i < kept.size(); ++i) {
            kept_rows += kept[i] == "1";
            if (door[i]) removed_noise += std::stoul(removed[i]);
        }
        EXPECT_EQ(kept_rows, b.scans_kept);
        EXPECT_EQ(removed_noise, b.points_removed_noise);
        EXPECT_GT(b.points_removed_noise, 0u);
        fs::remove_all(dir / "off");
        fs::remove_all(dir / "on");
    }
}

// kfd-icp-slam's configuration with its [KFD] part replaced by `kfd` (a pipeline of other
// stages: the shipped sections of the stages it leaves out would be errors).
std::string configWithKfd(const std::string& path, const std::string& kfd) {
    std::string ini = text(kConfig);
    ini = ini.substr(0, ini.find("\n[KFD]") + 1) + kfd;
    std::ofstream(path) << ini;
    return path;
}

// With only the evidence denoiser every scan is kept and pending until the next one: the last
// one of the log waits for the end (finish()). It must reach ICP, get its pose and row, and
// count, in the run and in the pre-pass that matches a drop rate.
TEST(IcpSlamRunner, NextScanRunsTheLastPendingScanOfTheLog) {
    TempDir dir;
    const std::string off = configWithKfd(
        dir / "off.ini",
        "[KFD]\npipeline = evidence_denoise\n[KFD.evidence_denoise]\nnext_scan = false\n");
    const std::string on = configWithKfd(
        dir / "on.ini",
        "[KFD]\npipeline = evidence_denoise\n[KFD.evidence_denoise]\nnext_scan = true\n");
    const auto [a, b] = runOffOn(kOffice, dir, off, on);
    EXPECT_EQ(b.pipeline.stages, std::vector<std::string>{"evidence_denoise"});
    EXPECT_EQ(b.scans_in, a.scans_in);
    EXPECT_EQ(b.scans_kept, a.scans_kept);
    EXPECT_EQ(b.scans_kept, b.scans_in);
    EXPECT_EQ(b.icp_runs, a.icp_runs);
    const auto traj = kfd::readTum(dir / "on/trajectory.tum");
    ASSERT_EQ(traj.size(), b.scans_in);
    const auto rows = csvRows(dir / "on/scans.csv");
    ASSERT_EQ(rows.size(), b.scans_in + 1);
    EXPECT_EQ(csvColumn(rows, "index").back(), std::to_string(b.scans_in - 1));
    EXPECT_EQ(csvColumn(rows, "kept").back(), "1");
    // Every row is the scan's final record: a pending one has no clusters yet (the denoise
    // stage had not run); the clusters do not depend on next_scan (the removals do).
    EXPECT_EQ(csvColumn(rows, "clusters"), csvColumn(csvRows(dir / "off/scans.csv"), "clusters"));
    EXPECT_NE(csvColumn(rows, "clusters").back(), "0");
    // The pre-pass of --match-drop-of: the same target with and without next_scan.
    auto o = options(kOffice, dir / "dec_off", kfd::PrefilterMode::Decimate);
    o.write_map = false;
    o.match_drop_of = kfd::PrefilterMode::Kfd;
    o.config_file = off;
    const auto c = runAndReport(o);
    o.output_dir = dir / "dec_on";
    o.config_file = on;
    const auto d = runAndReport(o);
    ASSERT_TRUE(c.target_drop_pct && d.target_drop_pct);
    EXPECT_EQ(*d.target_drop_pct, *c.target_drop_pct);
    EXPECT_EQ(d.scans_kept, c.scans_kept);
}

TEST(IcpSlamRunner, ModesAreNamedStageListsOfTheRegistry) {
    const auto& modes = kfd::prefilterModes();
    std::vector<std::string> names;
    for (const auto& m : modes) {
        names.push_back(m.name);
        EXPECT_FALSE(m.description.empty()) << m.name;
        EXPECT_STREQ(kfd::toString(m.mode), m.name.c_str());
        EXPECT_EQ(kfd::parsePrefilterMode(m.name), m.mode);
        for (const auto& s : m.stages)
            EXPECT_NE(kfd::defaultStageRegistry().find(s), nullptr) << m.name << ": " << s;
        kfd::Pipeline::Params kfd_params;
        kfd_params.stages = {"denoise"};  // the [KFD] list: only the kfd mode keeps it
        const auto p = kfd::pipelineForMode(m.mode, kfd_params);
        EXPECT_EQ(p.stages, m.uses_kfd_stages ? kfd_params.stages : m.stages) << m.name;
    }
    EXPECT_EQ(names, (std::vector<std::string>{"none", "odometry", "keyframe", "kfd", "dbscan",
                                               "radius", "sor", "decimate"}));
    EXPECT_EQ(modes[7].stages, (std::vector<std::string>{"decimate"}));
    // The baseline modes run "distance" and then the baseline, described by its stage's help.
    EXPECT_EQ(modes[6].stages, (std::vector<std::string>{"distance", "sor"}));
    EXPECT_NE(modes[6].description.find(kfd::defaultStageRegistry().find("sor")->help),
              std::string::npos);
}

TEST(IcpSlamRunner, ModesParseAndMapToPipelines) {
    EXPECT_EQ(kfd::parsePrefilterMode("dbscan"), kfd::PrefilterMode::Dbscan);
    EXPECT_THROW(kfd::parsePrefilterMode("fast"), kfd::ParameterError);
    kfd::Pipeline::Params p;
    EXPECT_TRUE(kfd::pipelineForMode(kfd::PrefilterMode::None, p).stages.empty());
    EXPECT_EQ(kfd::pipelineForMode(kfd::PrefilterMode::Odometry, p).stages,
              std::vector<std::string>{"motion"});
    EXPECT_EQ(kfd::pipelineForMode(kfd::PrefilterMode::Kfd, p).stages, p.stages);
}

TEST(IcpSlamRunner, EveryShippedSlamConfigLoads) {
    std::size_t n = 0;
    for (const auto& e :
         fs::directory_iterator(std::string(KFD_SOURCE_DIR) + "/share/kfd-icp-slam")) {
        SCOPED_TRACE(e.path().string());
        EXPECT_NO_THROW(kfd::loadConfigFile(e.path().string()));  // its [KFD] section
        ++n;
    }
    EXPECT_GE(n, 1u);
}

TEST(KfdIcpSlamCli, UsageErrorsAndHelp) {
    auto run = [](const std::string& args) {
        const std::string cmd =
            std::string("'") + KFD_ICP_SLAM_EXE + "' " + args + " > /dev/null 2>&1";
        const int st = std::system(cmd.c_str());
        return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    };
    EXPECT_EQ(run("--help"), 0);
    EXPECT_EQ(run(""), 2);
    EXPECT_EQ(run("x.ini --mode fast"), 2);
    EXPECT_EQ(run("/nonexistent.ini"), 1);
}

TEST(IcpSlamRunner, RadiusAndSorModesParseAndMapToPipelines) {
    EXPECT_EQ(kfd::parsePrefilterMode("radius"), kfd::PrefilterMode::Radius);
    EXPECT_EQ(kfd::parsePrefilterMode("sor"), kfd::PrefilterMode::Sor);
    EXPECT_STREQ(kfd::toString(kfd::PrefilterMode::Radius), "radius");
    EXPECT_STREQ(kfd::toString(kfd::PrefilterMode::Sor), "sor");
    EXPECT_THROW(kfd::parsePrefilterMode("Radius"), kfd::ParameterError);
    EXPECT_THROW(kfd::parsePrefilterMode("statistical"), kfd::ParameterError);
    try {
        kfd::parsePrefilterMode("fast");
        FAIL();
    } catch (const kfd::ParameterError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("radius"), std::string::npos) << what;
        EXPECT_NE(what.find("sor"), std::string::npos) << what;
    }
    kfd::Pipeline::Params p;  // the [KFD] parameters carry over into the modes
    p.get<kfd::RadiusStage>().radius_m = 0.5;
    p.get<kfd::SorStage>().k = 5;
    const auto radius = kfd::pipelineForMode(kfd::PrefilterMode::Radius, p);
    EXPECT_EQ(radius.stages, (std::vector<std::string>{"distance", "radius"}));
    EXPECT_EQ(radius.get<kfd::RadiusStage>().radius_m, 0.5);
    const auto sor = kfd::pipelineForMode(kfd::PrefilterMode::Sor, p);
    EXPECT_EQ(sor.stages, (std::vector<std::string>{"distance", "sor"}));
    EXPECT_EQ(sor.get<kfd::SorStage>().k, 5u);
    EXPECT_EQ(kfd::Pipeline(radius, kfd::defaultStageRegistry()).stages().size(),
              2u);  // both build
    EXPECT_EQ(kfd::Pipeline(sor, kfd::defaultStageRegistry()).stages().size(), 2u);
    // The command line accepts them: a missing config is bad input (1), not bad usage (2).
    auto run = [](const std::string& args) {
        const std::string cmd =
            std::string("'") + KFD_ICP_SLAM_EXE + "' " + args + " > /dev/null 2>&1";
        const int st = std::system(cmd.c_str());
        return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    };
    EXPECT_EQ(run("/nonexistent.ini --mode radius"), 1);
    EXPECT_EQ(run("/nonexistent.ini --mode sor"), 1);
    EXPECT_EQ(run("/nonexistent.ini --mode rad"), 2);
}

TEST(IcpSlamRunner, RadiusAndSorModesRunAndKeepEveryScan) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    for (auto mode : {kfd::PrefilterMode::Radius, kfd::PrefilterMode::Sor}) {
        SCOPED_TRACE(kfd::toString(mode));
        auto o = options(kSena, dir / kfd::toString(mode), mode);
        o.write_map = false;
        const auto s = runAndReport(o);
        EXPECT_EQ(s.scans_in, 224u);
        EXPECT_EQ(s.scans_kept, s.scans_in);  // denoisers never drop scans
        // Out-of-range and noise removals together (the noise alone is checked in
        // rawlog_filter_test's BaselineDenoisersCountTheirNoise).
        EXPECT_GT(s.points_removed, 0u);
        EXPECT_LT(s.points_removed, s.points_in / 2);
        EXPECT_EQ(s.pipeline.stages, (std::vector<std::string>{"distance", kfd::toString(mode)}));
        const std::string json = text(dir / (std::string(kfd::toString(mode)) + "/summary.json"));
        EXPECT_NE(json.find(std::string("\"mode\": \"") + kfd::toString(mode) + "\""),
                  std::string::npos);
    }
}

TEST(IcpSlamRunner, GroundTruthTrajectoryGivesAteAndAReport) {
    TempDir dir;
    kfd::SimulationOptions so;
    so.duration_s = 8.0;
    so.output = dir / "sim.rawlog";
    const auto sim = kfd::Simulator().run(so);
    auto o = options(sim.rawlog, dir / "out", kfd::PrefilterMode::None);
    o.ground_truth_tum = sim.ground_truth;
    const auto s = runAndReport(o);
    ASSERT_TRUE(s.ate_rmse.has_value());
    EXPECT_LT(*s.ate_rmse, 0.1);  // ICP-SLAM on clean simulated scans: centimetres
    EXPECT_NE(text(dir / "out/summary.json").find("\"ate_rmse_m\""), std::string::npos);
    const std::string report = text(dir / "out/report.md");
    EXPECT_NE(report.find("ATE RMSE"), std::string::npos);
    EXPECT_NE(report.find("map_figure.png"), std::string::npos);
    mrpt::img::CImage img;
    ASSERT_TRUE(img.loadFromFile(dir / "out/map_figure.png"));
    EXPECT_LE(std::max(img.getWidth(), img.getHeight()), 3000u);  // the figure's budget
    // The figure's caption names what it drew: ground truth and odometry here, neither on a
    // laser-only run without ground truth.
    auto caption = [&](const std::string& out) {
        const std::string md = text(out + "/report.md");
        const auto from = md.find("![");
        return md.substr(from, md.find('\n', from) - from);
    };
    const std::string full = caption(dir / "out");
    for (const char* layer : {"occupancy map", "estimate", "ground truth", "odometry"})
        EXPECT_NE(full.find(layer), std::string::npos) << layer << " in " << full;
    o = options(sim.rawlog, dir / "laser", kfd::PrefilterMode::None);
    o.laser_only = true;
    runAndReport(o);
    const std::string laser = caption(dir / "laser");
    EXPECT_NE(laser.find("estimate"), std::string::npos) << laser;
    for (const char* layer : {"ground truth", "odometry"})
        EXPECT_EQ(laser.find(layer), std::string::npos) << layer << " in " << laser;
}

// API users get the same protection as the app: the output folder appears only on commit, a
// cancelled run leaves nothing, and an input inside the output's names is refused.
TEST(IcpSlamRunner, OutputIsStagedUntilCommittedAndACancelledRunLeavesNothing) {
    TempDir dir;
    kfd::SimulationOptions so;
    so.duration_s = 2.0;
    so.output = dir / "sim.rawlog";
    const auto sim = kfd::Simulator().run(so);
    auto o = options(sim.rawlog, dir / "out", kfd::PrefilterMode::None);
    o.write_map = false;
    {
        const auto result = kfd::IcpSlamRunner().run(o);
        EXPECT_FALSE(fs::exists(dir / "out"));
        ASSERT_TRUE(result.output);
        EXPECT_TRUE(fs::exists(result.output->path() / "trajectory.tum"));
    }  // dropped uncommitted: nothing remains
    std::size_t entries = 0;
    for (const auto& e : fs::directory_iterator(dir.path)) entries += e.is_directory();
    EXPECT_EQ(entries, 0u);
    kfd::requestCancel(SIGINT);
    EXPECT_THROW(kfd::IcpSlamRunner().run(o), kfd::Cancelled);
    kfd::resetCancel();
    EXPECT_FALSE(fs::exists(dir / "out"));
    const auto result = kfd::IcpSlamRunner().run(o);
    result.output->commit();
    EXPECT_TRUE(fs::exists(dir / "out/trajectory.tum"));
    o.ground_truth_tum = dir / "out/trajectory.tum";
    EXPECT_THROW(kfd::IcpSlamRunner().run(o), kfd::PathError);
}

TEST(IcpSlamRunner, TruncatedRawlogIsAnErrorNotAShortRun) {
    const std::string real = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";
    if (!fs::exists(real)) GTEST_SKIP() << "missing " << real;
    TempDir dir;
    {
        const std::string data = kfd::test::fileBytes(real);
        std::ofstream(dir / "cut.rawlog", std::ios::binary) << data.substr(0, data.size() / 2);
    }
    auto o = options(dir / "cut.rawlog", dir / "out", kfd::PrefilterMode::None);
    o.write_map = false;
    try {
        kfd::IcpSlamRunner().run(o);
        ADD_FAILURE() << "a truncated rawlog ran to its end";
    } catch (const kfd::SlamError& e) {
        EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
    }
}

TEST(IcpSlamRunner, SummaryJsonKeepsEveryKeyInOrder) {
    kfd::IcpSlamSummary s;
    s.mode = kfd::PrefilterMode::Odometry;
    s.rawlog = "a \"quoted\" \\ path.rawlog";
    s.pipeline.stages = {"motion"};
    s.scans_in = 10;
    s.scans_kept = 4;
    s.dropped_pct = 60.0;
    s.ate_rmse = 0.125;
    s.relations = kfd::RelationsError{};
    s.relations->used = 7;
    s.relations_file = "gt.relations";
    const std::string json = kfd::toJson(s);
    std::size_t last = 0;
    for (const char* key : {"\"mode\": \"odometry\"",
                            "\"rawlog\": \"a \\\"quoted\\\" \\\\ path.rawlog\"",
                            "\"stages\"",
                            "\"motion\"",
                            "\"entries\"",
                            "\"scans_in\": 10",
                            "\"scans_kept\": 4",
                            "\"dropped_pct\": 60.0",
                            "\"points_in\"",
                            "\"points_removed\"",
                            "\"prefilter_us_per_scan\"",
                            "\"icp_ms_per_scan\"",
                            "\"icp_ms_per_kept_scan\"",
                            "\"cpu_s_total\"",
                            "\"wall_s_total\"",
                            "\"motion_distance_m\"",
                            "\"motion_angle_deg\"",
                            "\"ate_rmse_m\": 0.125",
                            "\"relations\"",
                            "\"file\": \"gt.relations\"",
                            "\"used\": 7",
                            "\"unmatched\"",
                            "\"trans_mean_m\"",
                            "\"trans_std_m\"",
                            "\"rot_mean_deg\"",
                            "\"rot_std_deg\"",
                            "\"trans2_mean_m2\"",
                            "\"trans2_std_m2\"",
                            "\"rot2_mean_deg2\"",
                            "\"rot2_std_deg2\""}) {
        const auto at = json.find(key, last);
        ASSERT_NE(at, std::string::npos) << key << " in\n" << json;
        last = at;
    }
    EXPECT_EQ(json.back(), '\n');
    s.ate_rmse.reset();
    s.relations.reset();
    const std::string bare = kfd::toJson(s);
    EXPECT_EQ(bare.find("ate_rmse_m"), std::string::npos);
    EXPECT_EQ(bare.find("relations"), std::string::npos);
}

TEST(IcpSlamRunner, KeyframeGuardsFollowTheSlamsLocalisationGate) {
    // sick-180-5hz.ini: ICP corrects after 0.2 m or 5 deg; kfd's guards (0.5 m, 15 deg) are
    // lowered to that. The every-scan variant has no gate: the guards stay.
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    auto o = options(kSena, dir / "gated", kfd::PrefilterMode::Kfd);
    o.write_map = false;
    const auto gated = runAndReport(o);
    EXPECT_DOUBLE_EQ(gated.guard_translation_m, 0.2);
    EXPECT_DOUBLE_EQ(gated.guard_rotation_deg, 5.0);
    EXPECT_EQ(gated.pipeline.get<kfd::KeyframeStage>().max_translation_m, 0.2);
    o.config_file = std::string(KFD_SOURCE_DIR) + "/share/kfd-icp-slam/sick-180-5hz-every-scan.ini";
    o.output_dir = dir / "every";
    const auto every = runAndReport(o);
    EXPECT_DOUBLE_EQ(every.guard_translation_m, 0.5);
    EXPECT_DOUBLE_EQ(every.guard_rotation_deg, 15.0);
    EXPECT_LE(every.scans_kept, gated.scans_kept);  // the gate's guards keep at least as many
    EXPECT_NE(text(dir / "gated/summary.json").find("\"guard_translation_m\": 0.2"),
              std::string::npos);
    // The lowering is reported, not silent: the guards as configured beside those used.
    EXPECT_DOUBLE_EQ(gated.guard_translation_m_configured, 0.5);
    EXPECT_DOUBLE_EQ(gated.guard_rotation_deg_configured, 15.0);
    EXPECT_NE(text(dir / "gated/summary.json").find("\"guard_translation_m_configured\": 0.5"),
              std::string::npos);
    EXPECT_NE(kfd::summaryText(gated).find("keyframe guards lowered to the SLAM's localisation "
                                           "gate: 0.5 -> 0.2 m, 15 -> 5 deg"),
              std::string::npos)
        << kfd::summaryText(gated);
    EXPECT_EQ(kfd::summaryText(every).find("guards"), std::string::npos);
}

TEST(IcpSlamRunner, ARejectedCorrectionIsReMatchedThroughTheDroppedScans) {
    // ICP on every scan with a minimum goodness most corrections miss: after each rejection
    // the scans kfd dropped since the last accepted correction go through ICP in order, then
    // the rejected scan again; their rows say icp_rematch and they count as kept.
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    std::string ini =
        text(std::string(KFD_SOURCE_DIR) + "/share/kfd-icp-slam/sick-180-5hz-every-scan.ini");
    const auto at = ini.find("minICPgoodnessToAccept = 0.40");
    ASSERT_NE(at, std::string::npos);
    ini.replace(at, 29, "minICPgoodnessToAccept = 0.90");
    const std::string config = dir / "strict.ini";
    std::ofstream(config) << ini;
    auto o = options(kSena, dir / "kfd", kfd::PrefilterMode::Kfd);
    o.config_file = config;  // with the map: report.md is written with it
    const auto s = runAndReport(o);
    EXPECT_GT(s.icp_rejected, 0u);
    EXPECT_GT(s.rematches, 0u);
    EXPECT_GT(s.scans_rematched, 0u);
    EXPECT_LE(s.rematches_recovered, s.rematches);
    EXPECT_EQ(s.scans_kept + s.scans_dropped + s.scans_skipped, s.scans_in);
    const auto csv = csvRows(dir / "kfd/scans.csv");
    ASSERT_FALSE(csv.empty());
    std::size_t kept = 0, rematched = 0;
    bool rematch_open = false;  // rematched rows are followed by the rejected scan's row
    for (std::size_t i = 1; i < csv.size(); ++i) {
        const auto& f = csv[i];
        ASSERT_GE(f.size(), 22u) << i;
        kept += f[3] == "1";
        if (f[4] == "icp_rematch") {
            ++rematched;
            EXPECT_EQ(f[3], "1") << i;
            rematch_open = true;
        } else if (rematch_open && f[3] == "1") {
            EXPECT_FALSE(f[21].empty()) << i;  // its correction's verdict (re-fed or not)
            rematch_open = false;
        }
    }
    const std::size_t rows = csv.size() - 1;
    EXPECT_EQ(rows, s.scans_in);
    EXPECT_EQ(kept, s.scans_kept);
    EXPECT_EQ(rematched, s.scans_rematched);
    EXPECT_NE(text(dir / "kfd/summary.json")
                  .find("\"scans_rematched\": " + std::to_string(s.scans_rematched)),
              std::string::npos);
    EXPECT_NE(text(dir / "kfd/report.md").find("re-matches after a rejected correction"),
              std::string::npos);
    // Nothing dropped, nothing to re-match: `none` is icp-slam as it is.
    o.mode = kfd::PrefilterMode::None;
    o.output_dir = dir / "none";
    const auto none = runAndReport(o);
    EXPECT_GT(none.icp_rejected, 0u);
    EXPECT_EQ(none.rematches, 0u);
    EXPECT_EQ(none.scans_rematched, 0u);
    EXPECT_EQ(none.gap_checks_failed, 0u);
}

// --- icp-slam's output keys and files (issue 23) ---------------------------------------------

namespace {

// A text file's rows split at blanks and tabs.
std::vector<std::vector<std::string>> rows(const std::string& path) {
    std::vector<std::vector<std::string>> out;
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ss(line);
        std::vector<std::string> fields;
        for (std::string f; ss >> f;) fields.push_back(f);
        out.push_back(fields);
    }
    return out;
}

// The files of `dir` whose names start with `prefix`.
std::set<std::string> filesStarting(const fs::path& dir, const std::string& prefix) {
    std::set<std::string> out;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().rfind(prefix, 0) == 0) out.insert(e.path().filename());
    return out;
}

template <class T>
void loadGz(const std::string& path, T& obj) {
    mrpt::io::CFileGZInputStream f(path);
    mrpt::serialization::archiveFrom(f) >> obj;
}

std::string simulatedLog(const fs::path& dir, double seconds) {
    kfd::SimulationOptions so;
    so.duration_s = seconds;
    so.output = dir / "sim.rawlog";
    return kfd::Simulator().run(so).rawlog;
}

}  // namespace

// A user switching from MRPT's icp-slam finds its files: every step's logs, the pose PDFs and 3D
// scenes every LOG_FREQUENCY steps, the final map and the map as text and as a grid image.
TEST(IcpSlamLogs, OutputKeysWriteIcpSlamsFilesInItsFormats) {
    TempDir dir;
    const std::string rawlog = simulatedLog(dir.path, 4.0);
    auto o = options(rawlog, dir / "out", kfd::PrefilterMode::Kfd);
    o.config_file = configWith(dir / "icp.ini", "MappingApplication",
                               {{"LOG_FREQUENCY", "7"},
                                {"SAVE_POSE_LOG", "1"},
                                {"SAVE_3D_SCENE", "true"},
                                {"SHOW_LASER_SCANS_3D", "true"},
                                {"occupancyGrid_count", "1"}});
    const auto s = runAndReport(o);
    EXPECT_TRUE(s.notices.empty());
    const std::size_t steps = s.entries;  // icp-slam's steps: a scan or an odometry reading
    ASSERT_GT(steps, 20u);
    // One line per step, numbered as log_estimated_path.txt: "step x y phi", "ms frames",
    // "step<TAB>bytes".
    for (const auto& [name, columns] :
         {std::pair{"log_estimated_path.txt", 4u}, std::pair{"log_odometry_path.txt", 4u},
          std::pair{"log_times.txt", 2u}, std::pair{"log_MemoryUsage.txt", 2u}}) {
        SCOPED_TRACE(name);
        const auto r = rows(dir / ("out/" + std::string(name)));
        ASSERT_EQ(r.size(), steps);
        for (std::size_t i = 0; i < r.size(); ++i) {
            ASSERT_EQ(r[i].size(), columns) << i;
            if (columns == 4u || std::string(name) == "log_MemoryUsage.txt") {
                EXPECT_EQ(r[i][0], std::to_string(i));
            }
        }
    }
    EXPECT_NE(text(dir / "out/log_MemoryUsage.txt").find("0\t"), std::string::npos);
    // The odometry accumulated from (0, 0, 0): the robot drove forward.
    const auto odo = rows(dir / "out/log_odometry_path.txt");
    EXPECT_EQ(odo.front()[1], "0.000000");
    EXPECT_GT(std::stod(odo.back()[1]) * std::stod(odo.back()[1]) +
                  std::stod(odo.back()[2]) * std::stod(odo.back()[2]),
              1.0);
    const auto times = rows(dir / "out/log_times.txt");
    EXPECT_GE(std::stoi(times.back()[1]), 1);  // frames in the map
    // Every 7th step, from step 0: the pose PDF (mean, then the 6x6 covariance) and the scene.
    std::set<std::string> pdfs, scenes;
    for (std::size_t k = 0; k < steps; k += 7) {
        pdfs.insert(kfd::format("mapbuild_posepdf_%03zu.txt", k));
        scenes.insert(kfd::format("buildingmap_%05zu.3Dscene", k));
    }
    EXPECT_EQ(filesStarting(dir / "out", "mapbuild_posepdf_"), pdfs);
    EXPECT_EQ(filesStarting(dir / "out", "buildingmap_"), scenes);
    const auto pdf = rows(dir / ("out/" + *pdfs.rbegin()));
    ASSERT_EQ(pdf.size(), 7u);
    for (const auto& r : pdf) EXPECT_EQ(r.size(), 6u);
    // Each scene opens as SceneViewer3D opens it: the ground, the map and the robot, the step's
    // scans (a step of an observations log is a scan or an odometry reading), and the mini-map.
    std::size_t with_scans = 0;
    for (const auto& name : scenes) {
        SCOPED_TRACE(name);
        mrpt::opengl::COpenGLScene scene;
        loadGz(dir / ("out/" + name), scene);
        const auto main = scene.getViewport("main");
        ASSERT_TRUE(main);
        EXPECT_GE(main->size(), 3u);
        EXPECT_TRUE(main->getByClass<mrpt::opengl::CGridPlaneXY>());
        with_scans += main->getByClass<mrpt::opengl::CPlanarLaserScan>() ? 1 : 0;
        ASSERT_TRUE(scene.getViewport("mini-map"));
        EXPECT_GE(scene.getViewport("mini-map")->size(), 2u);
    }
    EXPECT_GT(with_scans, 0u);
    // The final map as icp-slam names it, the same as kfd's final_map.simplemap.
    mrpt::maps::CSimpleMap mine, kfds;
    loadGz(dir / "out/_finalmap_.simplemap", mine);
    loadGz(dir / "out/final_map.simplemap", kfds);
    EXPECT_GT(mine.size(), 0u);
    EXPECT_EQ(mine.size(), kfds.size());
    // Each map of the builder: the point map as "x y z" text, the grid as an image and limits.
    const auto points = rows(dir / "out/_finalmaps_.txt_mrpt__maps__CSimplePointsMap_01.txt");
    ASSERT_GT(points.size(), 100u);
    EXPECT_EQ(points.front().size(), 3u);
    const std::string png = dir / "out/_finalmaps_.txt_mrpt__maps__COccupancyGridMap2D_00.png";
    mrpt::img::CImage img;
    ASSERT_TRUE(img.loadFromFile(png)) << png;
    EXPECT_GT(img.getWidth(), 10u);
    const auto limits =
        rows(dir / "out/_finalmaps_.txt_mrpt__maps__COccupancyGridMap2D_00_limits.txt");
    ASSERT_EQ(limits.size(), 2u);
    EXPECT_EQ(limits[1].size(), 4u);
    EXPECT_LT(std::stod(limits[1][0]), std::stod(limits[1][1]));
}

// The periodic files only when asked; without the map (--no-map) none of the final maps.
TEST(IcpSlamLogs, WithTheKeysOffOnlyThePerStepLogsAreWritten) {
    TempDir dir;
    const std::string rawlog = simulatedLog(dir.path, 2.0);
    auto o = options(rawlog, dir / "out", kfd::PrefilterMode::None);  // kConfig: keys off
    o.write_map = false;
    const auto s = runAndReport(o);
    EXPECT_TRUE(s.notices.empty());
    for (const char* f : {"log_estimated_path.txt", "log_odometry_path.txt", "log_times.txt",
                          "log_MemoryUsage.txt"})
        EXPECT_EQ(lines(dir / ("out/" + std::string(f))), s.entries) << f;
    for (const char* prefix : {"mapbuild_posepdf_", "buildingmap_", "_finalmap"})
        EXPECT_TRUE(filesStarting(dir / "out", prefix).empty()) << prefix;
    // SAVE_3D_SCENE and SAVE_POSE_LOG need LOG_FREQUENCY > 0: a notice each, nothing written.
    o.config_file = configWith(dir / "icp.ini", "MappingApplication",
                               {{"SAVE_POSE_LOG", "1"}, {"SAVE_3D_SCENE", "1"}});
    o.output_dir = dir / "out0";
    const auto zero = runAndReport(o);
    ASSERT_EQ(zero.notices.size(), 2u);
    EXPECT_NE(zero.notices[0].find("SAVE_POSE_LOG"), std::string::npos) << zero.notices[0];
    EXPECT_NE(zero.notices[1].find("SAVE_3D_SCENE"), std::string::npos) << zero.notices[1];
    EXPECT_NE(zero.notices[1].find("LOG_FREQUENCY = 0"), std::string::npos) << zero.notices[1];
    EXPECT_TRUE(filesStarting(dir / "out0", "buildingmap_").empty());
}

// MRPT's shipped icp-slam configurations open a live 3D window (SHOW_PROGRESS_3D_REAL_TIME):
// kfd-icp-slam runs them, warns on stderr naming the key, and says so in summary.json.
TEST(IcpSlamLogs, ALiveWindowIsAWarningNamingTheKey) {
    TempDir dir;
    const std::string rawlog = simulatedLog(dir.path, 2.0);
    const std::string config = configWith(
        dir / "icp.ini", "MappingApplication",
        {{"SHOW_PROGRESS_3D_REAL_TIME", "true"}, {"SHOW_PROGRESS_3D_REAL_TIME_DELAY_MS", "5"}});
    const std::string cmd = std::string("'") + KFD_ICP_SLAM_EXE + "' -q --no-map '" + config +
                            "' '" + rawlog + "' -o '" + (dir / "out") + "' > '" + (dir / "stdout") +
                            "' 2> '" + (dir / "stderr") + "'";
    const int st = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << text(dir / "stderr");
    const std::string err = text(dir / "stderr");
    EXPECT_EQ(
        err.rfind("kfd-icp-slam: warning: [MappingApplication] SHOW_PROGRESS_3D_REAL_TIME", 0), 0u)
        << err;
    EXPECT_NE(text(dir / "out/summary.json").find("SHOW_PROGRESS_3D_REAL_TIME"), std::string::npos);
    EXPECT_TRUE(fs::exists(dir / "out/log_times.txt"));
}

// The numbered names are outputs too: an existing OUT/buildingmap_00000.3Dscene that is the
// input log (a link to it) would be replaced at the end; refused before anything is written.
TEST(IcpSlamLogs, ANumberedOutputThatIsAnInputIsRefused) {
    EXPECT_TRUE(kfd::isIcpSlamNumberedOutput("buildingmap_00050.3Dscene"));
    EXPECT_TRUE(kfd::isIcpSlamNumberedOutput("mapbuild_posepdf_123.txt"));
    EXPECT_TRUE(
        kfd::isIcpSlamNumberedOutput("_finalmaps_.txt_mrpt__maps__CSimplePointsMap_00.txt"));
    EXPECT_FALSE(kfd::isIcpSlamNumberedOutput("buildingmap.rawlog"));
    TempDir dir;
    const std::string rawlog = simulatedLog(dir.path, 2.0);
    fs::create_directories(dir / "out");
    fs::create_symlink(rawlog, dir / "out/buildingmap_00000.3Dscene");
    const std::string before = text(rawlog);
    auto o = options(rawlog, dir / "out", kfd::PrefilterMode::None);
    try {
        runAndReport(o);
        ADD_FAILURE() << "an output replacing the input log was accepted";
    } catch (const kfd::PathError& e) {
        EXPECT_NE(std::string(e.what()).find("buildingmap_00000.3Dscene"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(text(rawlog), before);
    EXPECT_FALSE(fs::exists(dir / "out/log_times.txt"));
}

// With the same log and keys, kfd-icp-slam --mode none writes MRPT's icp-slam's files: the same
// names, the same bytes (the 3D scenes and the final map decompressed), the timings aside.
TEST(IcpSlamLogs, ModeNoneWritesTheFilesOfMrptIcpSlam) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    if (std::system("command -v icp-slam > /dev/null") != 0)
        GTEST_SKIP() << "MRPT's icp-slam not installed (mrpt-apps)";
    TempDir dir;
    // MRPT's grid-matching demo (an occupancy grid), no window, pose PDFs on, every 50 steps.
    const std::string demo =
        "/usr/share/mrpt/config_files/icp-slam/icp-slam_demo_classic_gridmatch.ini";
    if (!fs::exists(demo)) GTEST_SKIP() << "missing " << demo;
    std::string ini = text(demo);
    const std::string mrpt_out = dir / "mrpt";
    for (const auto& [key, value] :
         {std::pair{"SHOW_PROGRESS_3D_REAL_TIME=", "0"}, std::pair{"SAVE_POSE_LOG=", "1"},
          std::pair{"logOutput_dir=", mrpt_out.c_str()}}) {
        const auto at = ini.find(std::string("\n") + key);
        ASSERT_NE(at, std::string::npos) << key;
        ini.replace(at + 1, ini.find('\n', at + 1) - at - 1, std::string(key) + value);
    }
    std::ofstream(dir / "icp.ini") << ini;
    const std::string cmd =
        "icp-slam '" + (dir / "icp.ini") + "' '" + kSena + "' > '" + (dir / "icp.log") + "' 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << text(dir / "icp.log");
    auto o = options(kSena, dir / "kfd", kfd::PrefilterMode::None);
    o.config_file = dir / "icp.ini";
    runAndReport(o);
    std::size_t compared = 0;
    for (const auto& e : fs::directory_iterator(dir / "mrpt")) {
        const std::string name = e.path().filename();
        SCOPED_TRACE(name);
        const fs::path mine = dir / ("kfd/" + name);
        ASSERT_TRUE(fs::exists(mine));
        if (name == "log_times.txt" || name == "log_MemoryUsage.txt") {
            EXPECT_EQ(lines(mine), lines(e.path()));  // measured: the same lines, other numbers
        } else if (name.find(".3Dscene") != std::string::npos ||
                   name.find(".simplemap") != std::string::npos) {
            mrpt::io::CFileGZInputStream a(mine.string()), b(e.path().string());
            std::string da, db;
            char buf[65536];
            for (std::size_t n; (n = a.Read(buf, sizeof(buf))) > 0;) da.append(buf, n);
            for (std::size_t n; (n = b.Read(buf, sizeof(buf))) > 0;) db.append(buf, n);
            EXPECT_GT(da.size(), 0u);
            EXPECT_TRUE(da == db);
        } else {
            EXPECT_TRUE(text(mine) == text(e.path()));
        }
        ++compared;
    }
    EXPECT_GE(compared, 14u);  // 4 logs, 5 scenes, 5 pose PDFs, the final map, its image + limits
}
