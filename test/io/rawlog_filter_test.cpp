// kfd-filter end to end: RawlogFilter on real rawlogs, error handling, and the CLI.
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "kfd/algorithms/evidence_filter.h"
#include "kfd/io/rawlog_filter.h"
#include "kfd/mrpt/config.h"
#include "kfd/stages/core_stages.h"
#include "test_files.h"

namespace fs = std::filesystem;
using mrpt::obs::CObservation2DRangeScan;

namespace {

const std::string kSena =
    std::string(KFD_MRPT_DATASETS_DIR) + "/2006-01ENE-21-SENA_Telecom Faculty_one_loop_only.rawlog";
const std::string kMitCsail = std::string(KFD_DATASETS_DIR) + "/mit-csail/mit-csail.rawlog";

std::vector<mrpt::serialization::CSerializable::Ptr> readAll(const std::string& path) {
    kfd::RawlogSource source(path);
    std::vector<mrpt::serialization::CSerializable::Ptr> v;
    kfd::SourceEntry e;
    while (source.next(e)) e.forEachObject([&](const auto& obj) { v.push_back(obj); });
    return v;
}

std::vector<std::shared_ptr<CObservation2DRangeScan>> scansOf(
    const std::vector<mrpt::serialization::CSerializable::Ptr>& objs) {
    std::vector<std::shared_ptr<CObservation2DRangeScan>> scans;
    for (const auto& o : objs) {
        if (auto s = std::dynamic_pointer_cast<CObservation2DRangeScan>(o)) scans.push_back(s);
        if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(o))
            for (const auto& ob : *sf)
                if (auto s = std::dynamic_pointer_cast<CObservation2DRangeScan>(ob))
                    scans.push_back(s);
    }
    return scans;
}

mrpt::poses::CPose2D integratedOdometry(
    const std::vector<mrpt::serialization::CSerializable::Ptr>& objs) {
    mrpt::poses::CPose2D p;
    for (const auto& o : objs)
        if (auto a = std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(o))
            if (auto mv = a->getBestMovementEstimation()) p = p + mv->rawOdometryIncrementReading;
    return p;
}

using kfd::test::fileBytes;

struct TempDir : kfd::test::TempDir {
    TempDir()
        : kfd::test::TempDir("kfd_test_" +
                             std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                             "_") {}
};

// Checks what every filtered rawlog must satisfy against its input.
void checkConservation(const std::string& in, const std::string& out,
                       const kfd::RawlogFilterSummary& s) {
    const auto objs_in = readAll(in);
    const auto objs_out = readAll(out);
    EXPECT_EQ(objs_in.size(), s.objects_in);
    EXPECT_EQ(objs_out.size(), s.objects_out);
    EXPECT_EQ(s.objects_in, s.objects_out + s.objects_dropped + s.actions_merged);
    EXPECT_EQ(s.scans_in, s.scans_kept + s.scans_dropped);
    const auto scans_in = scansOf(objs_in);
    const auto scans_out = scansOf(objs_out);
    EXPECT_EQ(scans_in.size(), s.scans_in);
    ASSERT_EQ(scans_out.size(), s.scans_kept);

    // Kept scans are a subsequence of the input (by timestamp), with the same beams and ranges;
    // filtering only ever clears valid flags.
    std::size_t j = 0, cleared = 0;
    for (const auto& so : scans_out) {
        while (j < scans_in.size() && scans_in[j]->timestamp != so->timestamp) ++j;
        ASSERT_LT(j, scans_in.size()) << "output scan not found in the input, in order";
        const auto& si = scans_in[j++];
        ASSERT_EQ(so->getScanSize(), si->getScanSize());
        EXPECT_EQ(so->aperture, si->aperture);
        for (std::size_t i = 0; i < so->getScanSize(); ++i) {
            ASSERT_EQ(so->getScanRange(i), si->getScanRange(i));
            if (so->getScanRangeValidity(i)) {
                ASSERT_TRUE(si->getScanRangeValidity(i));
            }
            cleared += si->getScanRangeValidity(i) && !so->getScanRangeValidity(i);
        }
    }
    EXPECT_EQ(cleared, s.stageTotal("points_removed_range") + s.points_removed_noise);

    // Every non-scan observation survives, in order (observations layout).
    std::vector<std::string> others_in, others_out;
    for (const auto& o : objs_in)
        if (!std::dynamic_pointer_cast<CObservation2DRangeScan>(o) &&
            !std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(o) &&
            !std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(o))
            others_in.push_back(o->GetRuntimeClass()->className);
    for (const auto& o : objs_out)
        if (!std::dynamic_pointer_cast<CObservation2DRangeScan>(o) &&
            !std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(o) &&
            !std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(o))
            others_out.push_back(o->GetRuntimeClass()->className);
    EXPECT_EQ(others_in, others_out);

    // No odometry is lost: the composed actions add up to the same motion.
    const auto oi = integratedOdometry(objs_in), oo = integratedOdometry(objs_out);
    EXPECT_NEAR(oi.x(), oo.x(), 1e-6);
    EXPECT_NEAR(oi.y(), oo.y(), 1e-6);
    EXPECT_NEAR(oi.phi(), oo.phi(), 1e-6);
}

kfd::RawlogFilterOptions optionsFor(const std::string& in, const std::string& out) {
    kfd::RawlogFilterOptions o;
    o.input = in;
    o.output = out;
    o.pipeline = kfd::loadConfigFile(std::string(KFD_SHARE_DIR) + "/default.ini");
    return o;
}

int run(const std::string& cmd, std::string* output = nullptr) {
    FILE* p = popen((cmd + " 2>&1").c_str(), "r");
    if (!p) return -1;
    std::string text;
    char buf[4096];
    while (std::fgets(buf, sizeof(buf), p)) text += buf;
    const int status = pclose(p);
    if (output) *output = text;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

TEST(RawlogFilter, SenaSampleActionsLayoutConservesEverything) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing (install mrpt-common): " << kSena;
    TempDir dir;
    auto o = optionsFor(kSena, dir / "out.rawlog");
    o.stats_csv = dir / "stats.csv";
    std::size_t progress_calls = 0;
    o.on_progress = [&](const kfd::RawlogProgress&) { ++progress_calls; };
    o.progress_every = 50;
    const auto s = kfd::RawlogFilter().run(o);
    EXPECT_EQ(s.layout, "actions+sensory-frames");
    EXPECT_EQ(s.scans_in, 225u);
    EXPECT_GT(s.scans_dropped, 0u);
    EXPECT_GT(s.actions_merged, 0u);  // dropped frames had odometry to carry forward
    EXPECT_GT(progress_calls, 2u);
    checkConservation(kSena, o.output, s);

    // One CSV row per input scan, plus the header; column 4 is the kept (keyframe) flag.
    std::ifstream csv(o.stats_csv);
    std::size_t lines = 0, kept = 0;
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line.rfind("index,timestamp,sensor,kept,", 0), 0u) << line;
    ++lines;
    while (std::getline(csv, line)) {
        ++lines;
        std::stringstream fields(line);
        std::string field;
        for (int col = 0; col < 4; ++col) std::getline(fields, field, ',');
        kept += field == "1";
    }
    EXPECT_EQ(lines, s.scans_in + 1);
    EXPECT_EQ(kept, s.scans_kept);
}

TEST(RawlogFilter, SenaSampleActionsLayoutWithNextScanWritesTheSameObjects) {
    // Actions and sensory frames: a held keyframe's frame, and the actions after it, wait for
    // the next scan; the same objects come out, in order, with the same merged odometry.
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing (install mrpt-common): " << kSena;
    TempDir dir;
    auto on = optionsFor(kSena, dir / "on.rawlog");
    on.pipeline.get<kfd::EvidenceDenoiseStage>().next_scan = true;
    const auto off = optionsFor(kSena, dir / "off.rawlog");
    const auto a = kfd::RawlogFilter().run(on);
    const auto b = kfd::RawlogFilter().run(off);
    EXPECT_EQ(a.scans_kept, b.scans_kept);
    EXPECT_EQ(a.objects_out, b.objects_out);
    EXPECT_EQ(a.actions_merged, b.actions_merged);
    checkConservation(kSena, on.output, a);
    const auto oa = readAll(on.output), ob = readAll(off.output);
    ASSERT_EQ(oa.size(), ob.size());
    for (std::size_t k = 0; k < oa.size(); ++k)
        EXPECT_STREQ(oa[k]->GetRuntimeClass()->className, ob[k]->GetRuntimeClass()->className);
}

TEST(RawlogFilter, MitCsailObservationsLayoutConservesEverything) {
    if (!fs::exists(kMitCsail)) GTEST_SKIP() << "dataset missing: " << kMitCsail;
    TempDir dir;
    const auto o = optionsFor(kMitCsail, dir / "out.rawlog");
    const auto s = kfd::RawlogFilter().run(o);
    EXPECT_EQ(s.layout, "observations");
    EXPECT_EQ(s.scans_in, 1988u);  // datasets/README.md
    EXPECT_EQ(s.sensor.beams, 361u);
    EXPECT_NEAR(s.sensor.aperture_deg, 180.5, 0.01);  // the log's own aperture field
    EXPECT_GT(s.sensor.rate_hz, 1.0);                 // a few Hz (datasets/README.md: 5 Hz nominal)
    EXPECT_LT(s.sensor.rate_hz, 10.0);
    EXPECT_TRUE(s.sensor.odometry);
    EXPECT_GT(s.sensor.range_noise_m, 0.0);
    EXPECT_GT(s.scans_dropped, 0u);
    EXPECT_GT(s.points_removed_noise, 0u);
    checkConservation(kMitCsail, o.output, s);
}

TEST(RawlogFilter, OutputOpensInRawlogEdit) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    if (run("command -v rawlog-edit") != 0) GTEST_SKIP() << "rawlog-edit not installed (mrpt-apps)";
    TempDir dir;
    const auto o = optionsFor(kSena, dir / "out.rawlog");
    const auto s = kfd::RawlogFilter().run(o);
    std::string text;
    ASSERT_EQ(run("rawlog-edit --info -i " + quoted(o.output), &text), 0) << text;
    EXPECT_NE(text.find("Overall number of objects         : " + std::to_string(s.objects_out)),
              std::string::npos)
        << text;
}

// 30 steps of two 180-degree lasers (FRONT, REAR: 361 beams, FRONT 541 from step 20) and an
// odometry observation each.
static void writeTwoSensorLog(const std::string& path) {
    mrpt::io::CFileGZOutputStream f(path);
    auto arch = mrpt::serialization::archiveFrom(f);
    for (int k = 0; k < 30; ++k) {
        for (const char* label : {"FRONT", "REAR"}) {
            CObservation2DRangeScan s;
            s.sensorLabel = label;
            s.timestamp = mrpt::Clock::fromDouble(1000.0 + 0.1 * k);
            const std::size_t beams = (k >= 20 && label[0] == 'F') ? 541 : 361;
            s.aperture = static_cast<float>(M_PI);
            s.resizeScanAndAssign(beams, 4.0f, true);
            arch << s;
        }
        mrpt::obs::CObservationOdometry odo;
        odo.timestamp = mrpt::Clock::fromDouble(1000.0 + 0.1 * k);
        arch << odo;
    }
}

TEST(RawlogFilter, TwoSensorsAndAGeometryChangeInOneLog) {
    TempDir dir;
    const std::string in = dir / "synthetic.rawlog";
    writeTwoSensorLog(in);
    auto o = optionsFor(in, dir / "out.rawlog");
    const auto s = kfd::RawlogFilter().run(o);
    EXPECT_EQ(s.sensors, 2u);
    EXPECT_EQ(s.geometry_resets, 1u);
    EXPECT_EQ(s.scans_in, 60u);
    // A first scan per sensor, plus the first scan after FRONT's geometry change.
    EXPECT_GE(s.scans_kept, 3u);
    checkConservation(in, o.output, s);
}

TEST(RawlogFilter, TwoSensorsAndAGeometryChangeWithNextScanConserveEverything) {
    // The same log with next_scan: kept scans are held for their sensor's next one; the
    // output keeps the input's order and loses nothing.
    TempDir dir;
    const std::string in = dir / "synthetic.rawlog";
    writeTwoSensorLog(in);
    auto o = optionsFor(in, dir / "out.rawlog");
    auto off = o;
    off.output = dir / "off.rawlog";
    o.pipeline.get<kfd::EvidenceDenoiseStage>().next_scan = true;
    const auto s = kfd::RawlogFilter().run(o);
    const auto t = kfd::RawlogFilter().run(off);
    EXPECT_EQ(s.geometry_resets, 1u);
    EXPECT_EQ(s.scans_kept, t.scans_kept);
    EXPECT_EQ(s.objects_out, t.objects_out);
    checkConservation(in, o.output, s);
}

TEST(RawlogFilter, NextScanKeepsTheSameScansInTheSameOrderOnTheBundledLog) {
    // rawlogs/office-mit-0.752.rawlog with the default config, next_scan off and on: the same
    // kept scans (stamps, ranges) and objects in the same order, the stats rows in input order;
    // only valid flags may differ, and all of it conserved.
    const std::string log = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";
    TempDir dir;
    auto on = optionsFor(log, dir / "on.rawlog");
    on.pipeline.get<kfd::EvidenceDenoiseStage>().next_scan = true;
    on.stats_csv = dir / "on.csv";
    auto off = optionsFor(log, dir / "off.rawlog");
    off.stats_csv = dir / "off.csv";
    const auto a = kfd::RawlogFilter().run(on);
    const auto b = kfd::RawlogFilter().run(off);
    EXPECT_EQ(a.scans_in, b.scans_in);
    EXPECT_EQ(a.scans_kept, b.scans_kept);
    EXPECT_EQ(a.objects_out, b.objects_out);
    EXPECT_EQ(a.stageTotal("points_removed_range"), b.stageTotal("points_removed_range"));
    checkConservation(log, on.output, a);
    const auto sa = scansOf(readAll(on.output)), sb = scansOf(readAll(off.output));
    ASSERT_EQ(sa.size(), sb.size());
    std::size_t differ = 0;
    for (std::size_t k = 0; k < sa.size(); ++k) {
        ASSERT_EQ(sa[k]->timestamp, sb[k]->timestamp) << k;
        ASSERT_EQ(sa[k]->getScanSize(), sb[k]->getScanSize());
        for (std::size_t i = 0; i < sa[k]->getScanSize(); ++i) {
            ASSERT_EQ(sa[k]->getScanRange(i), sb[k]->getScanRange(i));
            differ += sa[k]->getScanRangeValidity(i) != sb[k]->getScanRangeValidity(i);
        }
    }
    EXPECT_LT(differ, a.points_in / 100);  // the denoiser's verdicts differ on a few returns
    // Each line's first field (up to `sep`): the CSV's index, the CARMEN line's kind.
    auto firstFields = [](const std::string& path, char sep) {
        std::ifstream f(path);
        std::vector<std::string> v;
        std::string line;
        while (std::getline(f, line)) v.push_back(line.substr(0, line.find(sep)));
        return v;
    };
    const auto ia = firstFields(on.stats_csv, ',');
    EXPECT_EQ(ia, firstFields(off.stats_csv, ','));
    EXPECT_EQ(ia.size(), a.scans_in + 1);  // a header and one row per scan

    // A CARMEN output: the same kinds of line in the same order.
    on.output = dir / "on.clf";
    off.output = dir / "off.clf";
    on.stats_csv = off.stats_csv = "";
    kfd::RawlogFilter().run(on);
    kfd::RawlogFilter().run(off);
    const auto ka = firstFields(on.output, ' ');
    EXPECT_EQ(ka, firstFields(off.output, ' '));
    EXPECT_GT(ka.size(), a.scans_kept);
}

namespace {

// An observations-layout rawlog of one sensor in a round room (361 beams over 180 deg, 4 m) at
// the given stamps, each range with Gaussian noise of `sigma_m`, and odometry at rest.
void writeRoom(const std::string& path, const std::vector<double>& stamps, double sigma_m) {
    mrpt::io::CFileGZOutputStream f(path);
    auto arch = mrpt::serialization::archiveFrom(f);
    std::mt19937 rng(7);
    std::normal_distribution<float> noise(0.0f, static_cast<float>(sigma_m));
    for (double t : stamps) {
        CObservation2DRangeScan s;
        s.sensorLabel = "LASER";
        s.timestamp = mrpt::Clock::fromDouble(t);
        s.aperture = static_cast<float>(M_PI);
        s.maxRange = 20.0f;
        s.resizeScanAndAssign(361, 4.0f, true);
        for (std::size_t i = 0; i < 361; ++i) s.setScanRange(i, 4.0f + noise(rng));
        arch << s;
        mrpt::obs::CObservationOdometry odo;
        odo.timestamp = s.timestamp;
        arch << odo;
    }
}

}  // namespace

// The rate is the mean over the whole log, labelled, with the median interval: a log at 10 Hz
// for its first 60 scans, then a 10 s gap, then 20 more (the first 50 scans alone say 10 Hz).
TEST(RawlogFilter, TheRateIsTheLogsMeanAndTheMedianIntervalIsPrintedBeside) {
    TempDir dir;
    std::vector<double> stamps;
    for (int k = 0; k < 80; ++k) stamps.push_back(1000.0 + 0.1 * k + (k >= 60 ? 10.0 : 0.0));
    writeRoom(dir / "gap.rawlog", stamps, 0.0);
    const auto s = kfd::RawlogFilter().run(optionsFor(dir / "gap.rawlog", dir / "out.rawlog"));
    const double mean = 79.0 / (stamps.back() - stamps.front());  // 79 intervals over 17.9 s
    EXPECT_NEAR(s.sensor.rate_hz, mean, 1e-6);
    EXPECT_NEAR(s.sensor.median_interval_s, 0.1, 1e-5);
    std::string text;
    ASSERT_EQ(run(quoted(KFD_FILTER_EXE) + " -q -i " + quoted(dir / "gap.rawlog") + " -o " +
                      quoted(dir / "out2.rawlog"),
                  &text),
              0)
        << text;
    char want[64];
    std::snprintf(want, sizeof(want), ", %.1f Hz mean (median interval 0.100 s)", mean);
    EXPECT_NE(text.find(want), std::string::npos) << want << " in\n" << text;
}

// Scans quieter than the evidence denoiser's floor (1 cm): the summary says the noise used is
// the floor and what the residuals measured, not "from the scans' residuals".
TEST(RawlogFilter, ARangeNoiseBelowTheFloorIsLabelledTheFloorWithTheMeasuredValue) {
    TempDir dir;
    std::vector<double> stamps;
    for (int k = 0; k < 40; ++k) stamps.push_back(1000.0 + 0.2 * k);
    writeRoom(dir / "quiet.rawlog", stamps, 0.003);  // 3 mm
    const auto s = kfd::RawlogFilter().run(optionsFor(dir / "quiet.rawlog", dir / "out.rawlog"));
    const double floor = kfd::EvidenceFilter::Params{}.min_sigma_m;
    EXPECT_EQ(s.sensor.range_noise_floor_m, floor);
    EXPECT_FALSE(s.sensor.range_noise_configured);
    EXPECT_NEAR(s.sensor.range_noise_m, floor, 1e-12);            // used: the floor
    EXPECT_NEAR(s.sensor.range_noise_measured_m, 0.003, 0.0015);  // measured: about 3 mm
    std::string text;
    ASSERT_EQ(run(quoted(KFD_FILTER_EXE) + " -q -i " + quoted(dir / "quiet.rawlog") + " -o " +
                      quoted(dir / "out2.rawlog"),
                  &text),
              0)
        << text;
    char want[128];
    std::snprintf(want, sizeof(want),
                  "range noise %.1f cm (the estimate's floor; the scans' residuals gave %.1f cm)",
                  100.0 * floor, 100.0 * s.sensor.range_noise_measured_m);
    EXPECT_NE(text.find(want), std::string::npos) << want << " in\n" << text;
    // sigma_m set: the value is labelled as configured.
    std::ofstream(dir / "fixed.ini") << "[KFD]\nvariant = evidence\nsigma_m = 0.02\n";
    ASSERT_EQ(run(quoted(KFD_FILTER_EXE) + " -q -c " + quoted(dir / "fixed.ini") + " -i " +
                      quoted(dir / "quiet.rawlog") + " -o " + quoted(dir / "out3.rawlog"),
                  &text),
              0)
        << text;
    EXPECT_NE(text.find("range noise 2.0 cm (configured: sigma_m)"), std::string::npos) << text;
}

// A CARMEN input: "objects in" counts the same unit as "out" (MRPT objects), the lines they
// were read from labelled beside.
TEST(RawlogFilter, ACarmenInputCountsObjectsOnBothSidesAndLabelsTheLines) {
    TempDir dir;
    {
        std::ofstream f(dir / "tiny.clf");
        f << "# a hand-made log\nPARAM robot_front_laser_max 50\n";
        for (int k = 0; k < 6; ++k) {
            f << "FLASER 20";
            for (int i = 0; i < 20; ++i) f << " " << (3.0 + 0.01 * i);
            f << " 0 0 0 " << 0.3 * k << " 0 0 " << 100.0 + 0.2 * k << " host 0\n";
        }
    }
    const auto s = kfd::RawlogFilter().run(optionsFor(dir / "tiny.clf", dir / "out.rawlog"));
    EXPECT_EQ(s.objects_in, 8u);  // lines
    EXPECT_EQ(s.objects_converted, readAll(dir / "out.rawlog").size() + s.objects_dropped);
    EXPECT_EQ(s.objects_converted, s.objects_out + s.objects_dropped + s.actions_merged);
    EXPECT_GT(s.objects_converted, s.objects_in);  // a scan and its odometry per FLASER line
    std::string text;
    ASSERT_EQ(run(quoted(KFD_FILTER_EXE) + " -q -i " + quoted(dir / "tiny.clf") + " -o " +
                      quoted(dir / "out2.rawlog"),
                  &text),
              0)
        << text;
    const std::string want = "  objects  in " + std::to_string(s.objects_converted) +
                             " (read from 8 CARMEN lines), out " + std::to_string(s.objects_out) +
                             ", dropped " + std::to_string(s.objects_dropped);
    EXPECT_NE(text.find(want), std::string::npos) << want << " in\n" << text;
}

TEST(RawlogFilter, MissingInputIsAnError) {
    TempDir dir;
    auto o = optionsFor(dir / "nothere.rawlog", dir / "out.rawlog");
    EXPECT_THROW(kfd::RawlogFilter().run(o), kfd::RawlogError);
    EXPECT_FALSE(fs::exists(o.output));
}

TEST(RawlogFilter, NonRawlogInputLeavesNoOutput) {
    TempDir dir;
    const std::string in = dir / "notes.rawlog";
    std::ofstream(in) << "this is not a rawlog\n";
    auto o = optionsFor(in, dir / "out.rawlog");
    try {
        kfd::RawlogFilter().run(o);
        FAIL() << "expected RawlogError";
    } catch (const kfd::RawlogError& e) {
        EXPECT_NE(std::string(e.what()).find("rawlog"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(o.output));
    for (const auto& e : fs::directory_iterator(dir.path))
        EXPECT_EQ(e.path().filename().string().find("out.rawlog"), std::string::npos)
            << "temporary file left behind: " << e.path();
    for (const auto& e : fs::directory_iterator(dir.path))  // the temporary names: .out.kfd-tmp-*
        EXPECT_EQ(e.path().filename().string().find("kfd-tmp"), std::string::npos)
            << "temporary file left behind: " << e.path();
}

TEST(RawlogFilter, TruncatedInputIsAnErrorAndLeavesNoOutput) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    const std::string in = dir / "truncated.rawlog";
    const std::string bytes = fileBytes(kSena);
    std::ofstream(in, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    auto o = optionsFor(in, dir / "out.rawlog");
    EXPECT_THROW(kfd::RawlogFilter().run(o), kfd::RawlogError);
    EXPECT_FALSE(fs::exists(o.output));
}

TEST(RawlogFilter, NeverWritesOverTheInput) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    const std::string in = dir / "in.rawlog";
    fs::copy_file(kSena, in);
    const std::string before = fileBytes(in);
    auto o = optionsFor(in, in);
    EXPECT_THROW(kfd::RawlogFilter().run(o), kfd::RawlogError);
    EXPECT_EQ(fileBytes(in), before);
    o.output = dir / "out.rawlog";
    kfd::RawlogFilter().run(o);
    EXPECT_EQ(fileBytes(in), before);
}

TEST(KfdFilterCli, HelpAndUsageErrors) {
    std::string text;
    EXPECT_EQ(run(quoted(KFD_FILTER_EXE) + " --help", &text), 0);
    EXPECT_NE(text.find("--stats"), std::string::npos);
    EXPECT_EQ(run(quoted(KFD_FILTER_EXE), &text), 2);
    EXPECT_NE(text.find("no input"), std::string::npos) << text;
    EXPECT_EQ(run(quoted(KFD_FILTER_EXE) + " --bogus", &text), 2);
}

TEST(KfdFilterCli, BadConfigNamesTheKeyAndFails) {
    TempDir dir;
    std::ofstream(dir / "bad.ini") << "[KFD]\nwindw = 3\n";
    std::string text;
    EXPECT_EQ(run(quoted(KFD_FILTER_EXE) + " -c " + quoted(dir / "bad.ini") + " -i " +
                      quoted(kSena) + " -o " + quoted(dir / "out.rawlog"),
                  &text),
              1);
    EXPECT_NE(text.find("windw"), std::string::npos) << text;
    EXPECT_FALSE(fs::exists(dir / "out.rawlog"));
}

TEST(KfdFilterCli, FiltersAndPrintsASummary) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    std::string text;
    ASSERT_EQ(
        run(quoted(KFD_FILTER_EXE) + " -c " + quoted(std::string(KFD_SHARE_DIR) + "/default.ini") +
                " -i " + quoted(kSena) + " -o " + quoted(dir / "out.rawlog"),
            &text),
        0)
        << text;
    EXPECT_NE(text.find("scans    in 225"), std::string::npos) << text;
    EXPECT_TRUE(fs::exists(dir / "out.rawlog"));
}

TEST(KfdFilterCli, WithoutAConfigUsesKfdsDefaultsAndPrintsTheSensor) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    std::string text, printed;
    ASSERT_EQ(
        run(quoted(KFD_FILTER_EXE) + " -i " + quoted(kSena) + " -o " + quoted(dir / "out.rawlog"),
            &text),
        0)
        << text;
    // SENA: 361 beams over 180 degrees with odometry; the noise is measured from its scans.
    EXPECT_NE(text.find("361 beams over 180.0 deg (0.500 deg per beam)"), std::string::npos)
        << text;
    EXPECT_NE(text.find(", odometry"), std::string::npos) << text;
    EXPECT_NE(text.find("range noise"), std::string::npos) << text;
    ASSERT_EQ(run(quoted(KFD_FILTER_EXE) + " --print-config", &printed), 0);
    EXPECT_EQ(printed, kfd::toIni(kfd::kfdDefaults()));
    EXPECT_NE(
        printed.find("pipeline = odometry_check, distance, track, view_keyframe, evidence_denoise"),
        std::string::npos)
        << printed;
}

TEST(RawlogFilter, BaselineDenoisersCountTheirNoise) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    for (const char* stage : {"radius", "sor", "dbscan"}) {
        SCOPED_TRACE(stage);
        auto o = optionsFor(kSena, dir / (std::string(stage) + ".rawlog"));
        o.pipeline.stages = {"distance", stage};
        const auto s = kfd::RawlogFilter().run(o);
        EXPECT_EQ(s.scans_kept, s.scans_in);  // denoisers never drop scans
        EXPECT_GT(s.points_removed_noise, 0u);
        checkConservation(kSena, o.output, s);  // every cleared flag is accounted for
    }
}

TEST(KfdFilterCli, RadiusAndSorFromAConfigFile) {
    if (!fs::exists(kSena)) GTEST_SKIP() << "MRPT sample missing: " << kSena;
    TempDir dir;
    std::ofstream(dir / "radius.ini") << "[KFD]\npipeline = distance, radius\nradius_m = 0.2\n"
                                         "radius_min_neighbors = 2\n";
    std::ofstream(dir / "sor.yaml") << "kfd:\n  pipeline: [distance, sor]\n  sor_k: 6\n"
                                       "  sor_std_mul: 1.5\n";
    for (const char* cfg : {"radius.ini", "sor.yaml"}) {
        std::string text;
        ASSERT_EQ(run(quoted(KFD_FILTER_EXE) + " -c " + quoted(dir / cfg) + " -i " + quoted(kSena) +
                          " -o " + quoted(dir / "out.rawlog"),
                      &text),
                  0)
            << text;
        EXPECT_NE(text.find("kept 225"), std::string::npos) << text;
        EXPECT_EQ(text.find(" 0 noise"), std::string::npos) << text;  // some noise removed
    }
}
