// kfd-simulate's logic: deterministic logs with consistent ground truth and labels, and the
// denoising-quality scorer on them.
#include <gtest/gtest.h>
#include <mrpt/obs/CObservation2DRangeScan.h>

#include <filesystem>
#include <fstream>
#include <utility>
#include <vector>

#include "kfd/eval/trajectory.h"
#include "kfd/io/rawlog_source.h"
#include "kfd/sim/denoise_quality.h"
#include "kfd/sim/simulator.h"
#include "kfd/stages/core_stages.h"
#include "test_files.h"

namespace fs = std::filesystem;

namespace {

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_sim_") {}
};

std::string bytes(const std::string& p) { return kfd::test::fileBytes(p); }

kfd::SimulationOptions shortRun(const std::string& out) {
    kfd::SimulationOptions o;
    o.duration_s = 3.0;
    o.output = out;
    return o;
}

}  // namespace

// kfd-simulate's progress line counts the scans written as it goes, not "0 scans" to the end.
TEST(Simulator, ProgressCountsTheScansWrittenAsTheRunGoes) {
    TempDir dir;
    auto o = shortRun(dir / "sim.rawlog");  // 3 s at 40 Hz: 120 scans
    o.progress_every = 25;
    std::vector<std::pair<double, std::size_t>> calls;
    o.on_progress = [&](double f, std::size_t scans) { calls.emplace_back(f, scans); };
    const auto s = kfd::Simulator().run(o);
    ASSERT_GE(calls.size(), 3u);
    EXPECT_GT(calls.front().second, 0u);
    EXPECT_LT(calls.front().second, s.scans);         // before the end, already counting
    for (std::size_t i = 1; i < calls.size(); ++i) {  // the last call may repeat the count
        if (i + 1 < calls.size()) {
            EXPECT_GT(calls[i].second, calls[i - 1].second);
        }
        EXPECT_GE(calls[i].second, calls[i - 1].second);
        EXPECT_GE(calls[i].first, calls[i - 1].first);
    }
    EXPECT_EQ(calls.back(), std::make_pair(1.0, s.scans));
}

TEST(Simulator, SameOptionsAndSeedGiveIdenticalFiles) {
    TempDir dir;
    const auto a = kfd::Simulator().run(shortRun(dir / "a/sim.rawlog"));
    const auto b = kfd::Simulator().run(shortRun(dir / "b/sim.rawlog"));
    EXPECT_EQ(bytes(a.rawlog), bytes(b.rawlog));
    EXPECT_EQ(bytes(a.labels), bytes(b.labels));
    EXPECT_EQ(bytes(a.ground_truth), bytes(b.ground_truth));
    auto o = shortRun(dir / "c/sim.rawlog");
    o.seed = 2;
    const auto c = kfd::Simulator().run(o);
    EXPECT_NE(bytes(a.labels), bytes(c.labels));
    EXPECT_EQ(bytes(a.ground_truth), bytes(c.ground_truth));  // the route does not depend on it
}

TEST(Simulator, MitSensorAtFortyHertzWithConsistentFiles) {
    TempDir dir;
    const auto s = kfd::Simulator().run(shortRun(dir / "sim.rawlog"));
    EXPECT_EQ(s.scans, 120u);  // 3 s at 40 Hz
    EXPECT_NEAR(s.duration_s, 3.0, 1e-9);
    EXPECT_EQ(kfd::readTum(s.ground_truth).size(), s.scans);
    EXPECT_EQ(kfd::readTum(s.odometry).size(), s.scans);
    // The rawlog: a 1081-beam, 270-degree scan and an odometry observation per step.
    kfd::RawlogSource source(s.rawlog);
    std::size_t scans = 0, objects = 0;
    kfd::SourceEntry e;
    while (source.next(e)) {
        objects = e.objects_read;
        EXPECT_EQ(e.kind, kfd::SourceEntry::Kind::Observation);
        e.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& sc) {
            ++scans;
            EXPECT_EQ(sc->getScanSize(), 1081u);
            EXPECT_NEAR(sc->aperture, 270.0 * M_PI / 180.0, 1e-5);
        });
    }
    EXPECT_EQ(scans, s.scans);
    EXPECT_EQ(objects, 2 * s.scans);
    // One label row per outlier beam.
    std::ifstream f(s.labels);
    std::string line;
    std::size_t rows = 0;
    std::getline(f, line);
    EXPECT_EQ(line, "scan,timestamp,beam,kind");
    while (std::getline(f, line)) ++rows;
    EXPECT_EQ(rows, s.noise_isolated + s.noise_clustered + s.noise_edge);
    EXPECT_GT(s.noise_isolated, 0u);
    EXPECT_GT(s.noise_edge, 0u);
}

TEST(Simulator, RouteMovesAtTheRequestedSpeedAndOdometryDrifts) {
    TempDir dir;
    auto o = shortRun(dir / "sim.rawlog");
    o.duration_s = 4.0;
    o.speed_mps = 0.575;
    const auto s = kfd::Simulator().run(o);
    const auto gt = kfd::readTum(s.ground_truth);
    const auto odo = kfd::readTum(s.odometry);
    // The office route starts facing its first leg: straight driving at 0.575 m/s.
    const double d = std::hypot(gt[40].pose.x - gt[0].pose.x, gt[40].pose.y - gt[0].pose.y);
    EXPECT_NEAR(d, 0.575, 1e-6);
    // Odometry starts at the origin and its path length differs from the truth (noise).
    EXPECT_NEAR(odo[0].pose.x, 0.0, 1e-9);
    const double od = std::hypot(odo[40].pose.x, odo[40].pose.y);
    EXPECT_NE(od, d);
    EXPECT_NEAR(od, d, 0.1);
}

TEST(Simulator, CorridorAndGazeboSensor) {
    TempDir dir;
    auto o = shortRun(dir / "c.rawlog");
    o.world = "corridor";
    o.sensor = "gazebo";
    const auto s = kfd::Simulator().run(o);
    EXPECT_EQ(s.scans, 30u);  // 3 s at 10 Hz
}

TEST(Simulator, BadOptionsAreClearErrors) {
    TempDir dir;
    auto o = shortRun(dir / "x.rawlog");
    o.world = "castle";
    EXPECT_THROW(kfd::Simulator().run(o), kfd::SimulationError);
    o = shortRun(dir / "x.rawlog");
    o.sensor = "lidar9000";
    EXPECT_THROW(kfd::Simulator().run(o), kfd::SimulationError);
    o = shortRun(dir / "x.rawlog");
    o.speed_mps = 0;
    EXPECT_THROW(kfd::Simulator().run(o), kfd::SimulationError);
    o = shortRun(dir / "x.rawlog");
    o.gridmap = dir / "missing.gridmap";
    o.route = dir / "missing.route";
    EXPECT_THROW(kfd::Simulator().run(o), kfd::SimulationError);
}

TEST(DenoiseQuality, RangeAwareFindsMoreNoiseThanTheReferenceOnLabelledScans) {
    TempDir dir;
    auto o = shortRun(dir / "sim.rawlog");
    o.duration_s = 5.0;
    const auto s = kfd::Simulator().run(o);
    kfd::Pipeline::Params p;
    p.stages = {"distance", "denoise"};
    const auto ref = kfd::evaluateDenoising(s.rawlog, s.labels, p);
    p.stages = {"distance", "range_aware_denoise"};
    const auto ra = kfd::evaluateDenoising(s.rawlog, s.labels, p);
    EXPECT_EQ(ref.scans, s.scans);
    EXPECT_EQ(ref.noise, s.noise_isolated + s.noise_clustered + s.noise_edge);
    EXPECT_EQ(ref.noise + ref.clean, ref.points);
    EXPECT_GT(ra.recall(), ref.recall() + 0.1);
    EXPECT_GT(ra.f1(), ref.f1());
    EXPECT_GT(ra.cleanKept(), 0.98);  // measured 0.989 on these 5 s
    EXPECT_GT(ra.recall(kfd::NoiseKind::Clustered), 0.9);
}

TEST(DenoiseQuality, NothingRemovedScoresZeroRecallAndKeepsEveryPoint) {
    TempDir dir;
    const auto s = kfd::Simulator().run(shortRun(dir / "sim.rawlog"));
    kfd::Pipeline::Params p;
    p.stages = {};
    const auto q = kfd::evaluateDenoising(s.rawlog, s.labels, p);
    EXPECT_EQ(q.removed_noise + q.removed_clean, 0u);
    EXPECT_DOUBLE_EQ(q.recall(), 0.0);
    EXPECT_DOUBLE_EQ(q.cleanKept(), 1.0);
    EXPECT_THROW(kfd::evaluateDenoising(s.rawlog, s.ground_truth, p), kfd::SimulationError);
}

TEST(DenoiseQuality, OnlyTheScansThePipelineKeepsAreScored) {
    // A dropped scan never reaches the SLAM: its noise is neither found nor missed.
    TempDir dir;
    const auto s = kfd::Simulator().run(shortRun(dir / "sim.rawlog"));
    kfd::Pipeline::Params all;
    all.stages = {};
    const auto every = kfd::evaluateDenoising(s.rawlog, s.labels, all);
    EXPECT_EQ(every.scans, s.scans);
    EXPECT_EQ(every.scored, every.scans);  // no keyframe stage: every scan kept and scored
    kfd::Pipeline::Params kf;
    kf.stages = {"keyframe"};
    const auto kept = kfd::evaluateDenoising(s.rawlog, s.labels, kf);
    EXPECT_EQ(kept.scans, s.scans);
    EXPECT_GT(kept.scored, 0u);
    EXPECT_LT(kept.scored, kept.scans);
    EXPECT_LT(kept.points, every.points);
    EXPECT_LT(kept.noise, every.noise);
    EXPECT_EQ(kept.removed_noise + kept.removed_clean, 0u);  // dropping is not denoising
}

TEST(Simulator, ReproducesTheBundledSampleLog) {
    // rawlogs/office-mit-0.752.* were made with: kfd-simulate -o ... -d 15 (defaults otherwise).
    TempDir dir;
    auto o = shortRun(dir / "office-mit-0.752.rawlog");
    o.duration_s = 15.0;
    const auto s = kfd::Simulator().run(o);
    const std::string bundled = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752";
    EXPECT_EQ(bytes(s.rawlog), bytes(bundled + ".rawlog"));
    EXPECT_EQ(bytes(s.labels), bytes(bundled + ".labels.csv"));
    EXPECT_EQ(bytes(s.ground_truth), bytes(bundled + ".gt.tum"));
    EXPECT_EQ(bytes(s.odometry), bytes(bundled + ".odom.tum"));
}

TEST(Simulator, GridmapAndRouteFiles) {
    const std::string gridmap =
        std::string(KFD_MRPT_DATASETS_DIR) + "/2006-MalagaCampus.gridmap.gz";
    if (!fs::exists(gridmap)) GTEST_SKIP() << "MRPT sample gridmap missing: " << gridmap;
    TempDir dir;
    std::ofstream(dir / "route.txt") << "# x y [stop_s [spin_deg]]\n0 0\n3 0 1 90\n";
    auto o = shortRun(dir / "m.rawlog");
    o.duration_s = 0;  // the whole route: 3 m at 0.752 m/s, 1 s stop, 90 deg at 45 deg/s
    o.gridmap = gridmap;
    o.route = dir / "route.txt";
    o.sensor = "gazebo";
    const auto s = kfd::Simulator().run(o);
    EXPECT_NEAR(s.distance_m, 3.0, 1e-6);
    EXPECT_NEAR(s.duration_s, 3.0 / 0.752 + 1.0 + 2.0, 0.25);
    std::ofstream(dir / "bad.txt") << "0 0\nthree 0\n";
    o.route = dir / "bad.txt";
    EXPECT_THROW(kfd::Simulator().run(o), kfd::SimulationError);
}
