// The bad-input table (issue 9, item 8): each row runs an app on a generated bad input and
// asserts the exit code, the first line of the message, what output was left and that the
// input is unchanged. This file: scans (item 2) and evaluation (item 5); output paths and
// truncated input are in bad_input_test.cpp.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "bad_logs.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using kfd::test::fileBytes;
using mrpt::obs::CObservation2DRangeScan;

const std::string kIcpConfig = std::string(KFD_SOURCE_DIR) + "/share/kfd-icp-slam/sick-180-5hz.ini";

struct Result {
    int status = -1;
    std::string out, err;
    std::string firstErrLine() const { return err.substr(0, err.find('\n')); }
};

/// Runs `exe args` through the shell, stdout and stderr kept apart.
Result run(const std::string& exe, const std::string& args) {
    const fs::path dir =
        fs::temp_directory_path() / ("kfd_bad_input_run_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const std::string cmd = "'" + exe + "' " + args + " > '" + (dir / "out").string() + "' 2> '" +
                            (dir / "err").string() + "'";
    const int st = std::system(cmd.c_str());
    Result r{WIFEXITED(st) ? WEXITSTATUS(st) : -1, fileBytes((dir / "out").string()),
             fileBytes((dir / "err").string())};
    fs::remove_all(dir);
    return r;
}

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_bad_input_") {}
};

std::string q(const std::string& s) { return "'" + s + "'"; }

// The names of the files in a folder (what a failed run left).
std::vector<std::string> listing(const fs::path& dir) {
    std::vector<std::string> v;
    for (const auto& e : fs::directory_iterator(dir)) v.push_back(e.path().filename().string());
    std::sort(v.begin(), v.end());
    return v;
}

// ---------------------------------------------------------------------------------------------
// scans (item 2): a bad scan is skipped or repaired, counted, never crashes and never aborts.
// ---------------------------------------------------------------------------------------------

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr float kInff = std::numeric_limits<float>::infinity();

void badScan(int k, CObservation2DRangeScan& s) {
    if (k == 4) s.aperture = 0.0f;   // read past a buffer in the clustering
    if (k == 6) s.resizeScan(0);     // aborted the whole log
    if (k == 8) s.aperture = kNaNf;  // never checked
    if (k == 10)
        for (std::size_t i = 0; i < s.getScanSize(); i += 2) s.setScanRange(i, -kInff);
    if (k == 12)
        for (std::size_t i = 0; i < s.getScanSize(); i += 2) s.setScanRange(i, 1e30f);
    if (k == 14)
        for (std::size_t i = 0; i < s.getScanSize(); i += 5) s.setScanRange(i, kNaNf);
}

// Every scan pathology of item 2 in one 30-step log; with `observations`, the observations
// layout with a NaN odometry observation too (that gave NaN poses with exit 0).
void writeBadScanLog(const std::string& path, bool observations = false) {
    if (!observations) {
        kfd::test::writeRoomLog(path, 30, badScan);
        return;
    }
    kfd::test::writeRoomObservationLog(path, 30, badScan, [](int k, mrpt::poses::CPose2D& p) {
        if (k == 16) p = mrpt::poses::CPose2D(std::nan(""), 0.0, 0.0);
    });
}

TEST(BadInputScans, FilterSkipsBadGeometryRepairsRangesAndKeepsTheInput) {
    TempDir dir;
    const std::string in = dir / "bad.rawlog", out = dir / "out.rawlog";
    writeBadScanLog(in);
    const std::string before = fileBytes(in);
    const Result r = run(KFD_FILTER_EXE,
                         "-q -i " + q(in) + " -o " + q(out) + " --stats " + q(dir / "stats.csv"));
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_NE(r.out.find("  skipped  3 (bad geometry, dropped from the output): no_beams 1 "
                         "bad_aperture 2\n"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find("  repaired "), std::string::npos) << r.out;
    EXPECT_TRUE(fs::exists(out));
    EXPECT_EQ(fileBytes(in), before);
    const std::string stats = fileBytes(dir / "stats.csv");
    EXPECT_NE(stats.find(",skipped:bad_aperture,"), std::string::npos);
    EXPECT_NE(stats.find(",skipped:no_beams,"), std::string::npos);
}

TEST(BadInputScans, IcpSlamInEveryModeSkipsBadScansAndWritesFinitePoses) {
    TempDir dir;
    for (const bool observations : {false, true})
        for (const char* mode :
             {"none", "odometry", "keyframe", "kfd", "dbscan", "radius", "sor", "decimate"}) {
            SCOPED_TRACE(std::string(mode) + (observations ? ", observations" : ", frames"));
            const std::string in = dir / "bad.rawlog";
            writeBadScanLog(in, observations);
            const std::string before = fileBytes(in);
            const std::string out =
                dir / (std::string("out-") + mode + (observations ? "-obs" : "-frames"));
            const Result r = run(KFD_ICP_SLAM_EXE, "-q " + q(kIcpConfig) + " " + q(in) + " -o " +
                                                       q(out) + " --no-map -m " + mode);
            ASSERT_EQ(r.status, 0) << r.err;
            EXPECT_EQ(fileBytes(in), before);
            const std::string json = fileBytes(out + "/summary.json");
            EXPECT_NE(json.find("\"scans_in\": 30"), std::string::npos) << json;
            EXPECT_NE(json.find("\"scans_skipped\": 3"), std::string::npos) << json;
            EXPECT_NE(json.find("\"bad_aperture\": 2"), std::string::npos) << json;
            EXPECT_NE(json.find("\"no_beams\": 1"), std::string::npos) << json;
            if (observations) {
                EXPECT_NE(json.find("\"odometry_bad\": 1"), std::string::npos) << json;
            }
            const std::string csv = fileBytes(out + "/scans.csv");
            EXPECT_NE(csv.find(",skipped:bad_aperture,"), std::string::npos);
            // Every pose finite (NaN odometry produced NaN poses with exit 0 before).
            std::ifstream tum(out + "/trajectory.tum");
            std::string line;
            std::size_t poses = 0;
            while (std::getline(tum, line)) {
                if (line.empty() || line[0] == '#') continue;
                ++poses;
                std::istringstream ss(line);
                double v = 0;
                while (ss >> v) EXPECT_TRUE(std::isfinite(v)) << line;
                EXPECT_TRUE(ss.eof()) << "not a number in: " << line;  // "nan" stops >>
            }
            EXPECT_EQ(poses, 30u);
        }
}

// ---------------------------------------------------------------------------------------------
// coordinates (issue 21, item 2): odometry and poses anywhere a double holds them.
// ---------------------------------------------------------------------------------------------

// The width and height of a PNG file (its IHDR chunk).
std::pair<unsigned, unsigned> pngSize(const std::string& path) {
    const std::string b = fileBytes(path);
    if (b.size() < 24 || b.compare(1, 3, "PNG") != 0) return {0, 0};
    auto be32 = [&](std::size_t i) {
        return (unsigned(static_cast<unsigned char>(b[i])) << 24) |
               (unsigned(static_cast<unsigned char>(b[i + 1])) << 16) |
               (unsigned(static_cast<unsigned char>(b[i + 2])) << 8) |
               unsigned(static_cast<unsigned char>(b[i + 3]));
    };
    return {be32(16), be32(20)};
}

TEST(BadInputCoordinates, IcpSlamWithOdometryFarFromTheOriginWritesEveryOutput) {
    // Before: UTM-like odometry segfaulted in the map image after the whole run (3.7 GB), 1e20
    // aborted on an MRPT assertion, a pose of 1e250 overflowed trajectory.tum's line buffer.
    TempDir dir;
    for (const double far : {4.52e5, 5.411e6, 1e20, 1e250}) {
        SCOPED_TRACE(far);
        const std::string in = dir / "far.rawlog";
        kfd::test::writeRoomObservationLog(in, 30, {}, [&](int, mrpt::poses::CPose2D& p) {
            p = mrpt::poses::CPose2D(p.x() + far, p.y() - far, p.phi());
        });
        const std::string before = fileBytes(in);
        const std::string out = dir / "out";
        fs::remove_all(out);
        const Result r =
            run(KFD_ICP_SLAM_EXE, "-q " + q(kIcpConfig) + " " + q(in) + " -o " + q(out));
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(fileBytes(in), before);
        EXPECT_EQ(listing(dir.path),
                  (std::vector<std::string>{"far.rawlog", "out"}));  // no staging
        for (const char* f :
             {"trajectory.tum", "log_estimated_path.txt", "scans.csv", "summary.json",
              "final_map.simplemap", "map.png", "map_figure.png", "report.md"})
            EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
        // The images are bounded by the map, not by the distance to the origin.
        for (const char* f : {"map.png", "map_figure.png"}) {
            const auto [w, h] = pngSize(out + "/" + f);
            EXPECT_GT(w, 0u) << f;
            EXPECT_LE(w, 6000u) << f;
            EXPECT_LE(h, 6000u) << f;
        }
        // One full line per scan in the log's frame: every number written whole, and where a
        // double still resolves the walk (UTM), the estimate follows the odometry.
        std::ifstream tum(out + "/trajectory.tum");
        std::string line;
        std::size_t poses = 0;
        while (std::getline(tum, line)) {
            if (line.empty() || line[0] == '#') continue;
            std::istringstream ss(line);
            double t = 0, x = 0, y = 0;
            ASSERT_TRUE(ss >> t >> x >> y) << line;
            EXPECT_NEAR(x / far, 1.0, 1e-5) << line;
            EXPECT_NEAR(y / far, -1.0, 1e-5) << line;
            if (far < 1e7) {
                EXPECT_NEAR(x - far, 0.05 * static_cast<double>(poses), 0.1) << line;
            }
            ++poses;
        }
        EXPECT_EQ(poses, 30u);
    }
}

// ---------------------------------------------------------------------------------------------
// evaluation (item 5): nothing matched, bad tolerances, zero quaternions, bad numbers.
// ---------------------------------------------------------------------------------------------

void writeTum(const std::string& path, double t0, int n, const char* extra_line = nullptr) {
    std::ofstream f(path);
    f << "# t x y z qx qy qz qw\n";
    for (int i = 0; i < n; ++i) f << t0 + i << " " << i << " 0 0 0 0 0 1\n";
    if (extra_line) f << extra_line << "\n";
}

struct EvalCase {
    const char* name;
    std::string args;  // after "EST.tum", with {gt} {rel} for the ground-truth files
    int status;
    std::string first;  // expected first line of stderr
};

TEST(BadInputEvaluation, EveryRowIsAnErrorThatNamesWhatIsWrong) {
    TempDir dir;
    const std::string est = dir / "est.tum", gt = dir / "gt.tum", far = dir / "far.tum",
                      zero_q = dir / "zero_q.tum", bad_num = dir / "bad_num.tum",
                      rel = dir / "gt.relations", far_rel = dir / "far.relations",
                      empty_rel = dir / "empty.relations";
    writeTum(est, 0.0, 10);
    writeTum(gt, 0.0, 10);
    writeTum(far, 1000.0, 10);
    writeTum(zero_q, 0.0, 3, "3 3 0 0 0 0 0 0");
    writeTum(bad_num, 0.0, 3, "3 3 0 0 0 0 0 1x");
    std::ofstream(rel) << "0 1 1 0 0 0 0 0\n";
    std::ofstream(far_rel) << "500 501 1 0 0 0 0 0\n";
    std::ofstream(empty_rel) << "# nothing\n";
    const std::vector<EvalCase> cases{
        {"ATE with no overlap", "--gt " + q(far), 1,
         "kfd-eval: ATE needs at least 2 matched poses (0 of 10 matched within 0.001000 s)"},
        {"relations with no match", "--relations " + q(far_rel), 1,
         "kfd-eval: no relation matched the trajectory: 1 relations, none with both stamps "
         "within 0.001000 s of a pose (10 poses)"},
        {"empty relations file", "--relations " + q(empty_rel), 1,
         "kfd-eval: no relations to evaluate"},
        {"negative --max-dt", "--gt " + q(gt) + " --max-dt -1", 2,
         "kfd-eval: --max-dt: must be finite and >= 0 (got -1.000000)"},
        {"zero --rpe-delta", "--gt " + q(gt) + " --rpe-delta 0", 2,
         "kfd-eval: --rpe-delta: must be finite and > 0 (got 0.000000)"},
        {"zero quaternion", "--gt " + q(zero_q), 1,
         "kfd-eval: " + zero_q + ":5: the quaternion has norm 0"},
        {"unparsable number", "--gt " + q(bad_num), 1,
         "kfd-eval: " + bad_num + ":5: expected 't x y z qx qy qz qw' (numbers)"},
        {"RPE step longer than the log", "--gt " + q(gt) + " --rpe-delta 100", 1,
         "kfd-eval: RPE: no pose pair 100.000000 s apart matched the estimate within 0.001000 "
         "s"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.name);
        const auto files_before = listing(dir.path);
        std::vector<std::string> bytes_before;
        for (const auto& f : files_before) bytes_before.push_back(fileBytes(dir / f));
        const Result r = run(KFD_EVAL_EXE, q(est) + " " + c.args);
        EXPECT_EQ(r.status, c.status) << r.err;
        EXPECT_EQ(r.firstErrLine(), c.first) << r.err;
        EXPECT_EQ(listing(dir.path), files_before);  // no output left
        for (std::size_t i = 0; i < files_before.size(); ++i)
            EXPECT_EQ(fileBytes(dir / files_before[i]), bytes_before[i]) << files_before[i];
    }
    // The same evaluation that matches is fine.
    EXPECT_EQ(run(KFD_EVAL_EXE, q(est) + " --gt " + q(gt) + " --relations " + q(rel)).status, 0);
}

// Issue 23: a relations file and a TUM trajectory both hold 8 numbers a line; each tool tells
// them by content. -g/--ground-truth takes either, -r/--relations and --gt one format each: a
// file under the other format's option is bad usage naming what the file is and which option
// takes it (before, `kfd-eval traj.tum -g x.relations` read the relations as a trajectory and
// printed an ATE, exit 0).
TEST(BadInputEvaluation, GroundTruthIsToldByContentAndTheWrongOptionIsNamed) {
    TempDir dir;
    const std::string est = dir / "est.tum", gt = dir / "gt.tum", rel = dir / "gt.relations",
                      part = dir / "part.tum";
    writeTum(est, 1000.0, 10);  // "t x 0 0 0 0 0 1": 1 m/s along x
    writeTum(gt, 1000.0, 10);
    writeTum(part, 1000.0, 4);  // covers 4 of the estimate's 10 poses
    const std::string garbage = dir / "garbage.bin";
    std::ofstream(garbage, std::ios::binary) << std::string("\x1f\x8b\x08\0\xff\xfe\n\x01", 8);
    {
        std::ofstream f(rel);  // consecutive stamps, t2 = the next row's t1
        for (int i = 0; i < 9; ++i) f << 1000 + i << " " << 1001 + i << " 1 0.1 0 0 0 0.05\n";
    }
    const Result by_content = run(KFD_EVAL_EXE, q(est) + " -g " + q(rel));
    EXPECT_EQ(by_content.status, 0) << by_content.err;
    EXPECT_NE(by_content.out.find("relations  " + rel + ": 9 used"), std::string::npos)
        << by_content.out;
    EXPECT_EQ(by_content.out.find("ATE"), std::string::npos) << by_content.out;
    const Result both = run(KFD_EVAL_EXE, q(est) + " -g " + q(gt) + " --ground-truth " + q(rel));
    EXPECT_EQ(both.status, 0) << both.err;
    EXPECT_NE(both.out.find("ATE        10 matched, 0 unmatched"), std::string::npos) << both.out;
    EXPECT_NE(both.out.find("relations  " + rel), std::string::npos) << both.out;

    const std::vector<EvalCase> cases{
        {"relations under --gt", "--gt " + q(rel), 2,
         "kfd-eval: --gt: " + rel +
             " is a relations file (t1 t2 x y z roll pitch yaw), not a TUM trajectory: give it "
             "with --relations or -g (9 rows: 9 with a later stamp in column 2, 8 with another "
             "row's stamp there, 9 with columns 5-7 zero; 0 with columns 4-6 zero, 0 with a "
             "unit quaternion in columns 5-8)"},
        {"TUM under --relations", "-r " + q(gt), 2,
         "kfd-eval: --relations: " + gt +
             " is a TUM trajectory (t x y z qx qy qz qw), not a relations file: give it with "
             "--gt or -g (10 rows: 0 with a later stamp in column 2, 0 with another row's stamp "
             "there, 10 with columns 5-7 zero; 10 with columns 4-6 zero, 10 with a unit "
             "quaternion in columns 5-8)"},
        {"a missing file under -g", "-g " + q(dir / "missing"), 1,
         "kfd-eval: ground truth not found: " + (dir / "missing")},
        {"binary garbage under -g", "-g " + q(garbage), 2,
         "kfd-eval: --ground-truth: " + garbage +
             " is neither clearly a TUM trajectory nor a relations file (0 rows: 0 with a later "
             "stamp in column 2, 0 with another row's stamp there, 0 with columns 5-7 zero; 0 "
             "with columns 4-6 zero, 0 with a unit quaternion in columns 5-8): give it with "
             "--relations or --gt"},
        {"two relations files", "-g " + q(rel) + " -r " + q(rel), 2,
         "kfd-eval: two relations files: " + rel + " and " + rel},
        {"ground truth for less than half of the estimate", "-g " + q(part), 1,
         "kfd-eval: ATE: only 4 of 10 estimated poses have a ground-truth pose within 0.001 s "
         "(6 unmatched): the ground truth must cover at least half of the trajectory (another "
         "log's ground truth, or a larger --max-dt?)"},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(c.name);
        const Result r = run(KFD_EVAL_EXE, q(est) + " " + c.args);
        EXPECT_EQ(r.status, c.status) << r.err;
        EXPECT_EQ(r.firstErrLine(), c.first) << r.err;
    }
    // The estimate itself must be a trajectory.
    const Result swapped = run(KFD_EVAL_EXE, q(rel) + " -g " + q(gt));
    EXPECT_EQ(swapped.status, 2);
    EXPECT_EQ(swapped.firstErrLine().rfind("kfd-eval: EST.tum: " + rel +
                                               " is a relations file (t1 t2 x y z roll pitch "
                                               "yaw), not an estimated TUM trajectory",
                                           0),
              0u)
        << swapped.err;
}

// kfd-icp-slam takes the same flags: -g is either format (it was the relations file only), a
// relations file under --gt is refused before the run.
TEST(BadInputEvaluation, IcpSlamTellsGroundTruthByContent) {
    TempDir dir;
    const std::string in = dir / "room.rawlog", rel = dir / "room.relations";
    kfd::test::writeRoomLog(in, 10);
    const std::string slam = "-q " + q(kIcpConfig) + " " + q(in) + " --no-map -o ";
    const Result first = run(KFD_ICP_SLAM_EXE, slam + q(dir / "first"));
    ASSERT_EQ(first.status, 0) << first.err;
    const std::string traj = dir / "first/trajectory.tum";
    {
        std::ifstream f(traj);
        std::ofstream r(rel);
        std::string line, prev;
        while (std::getline(f, line)) {
            if (line.empty() || line[0] == '#') continue;
            const std::string t = line.substr(0, line.find(' '));
            if (!prev.empty()) r << prev << " " << t << " 0.05 0.001 0 0 0 0.001\n";
            prev = t;
        }
    }
    const Result r =
        run(KFD_ICP_SLAM_EXE, slam + q(dir / "second") + " -g " + q(traj) + " -g " + q(rel));
    EXPECT_EQ(r.status, 0) << r.err;
    const std::string json = fileBytes(dir / "second/summary.json");
    EXPECT_NE(json.find("\"ate_rmse_m\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"relations\""), std::string::npos) << json;

    const Result wrong = run(KFD_ICP_SLAM_EXE, slam + q(dir / "third") + " --gt " + q(rel));
    EXPECT_EQ(wrong.status, 2) << wrong.err;
    EXPECT_EQ(wrong.firstErrLine().rfind("kfd-icp-slam: --gt: " + rel + " is a relations file", 0),
              0u)
        << wrong.err;
    EXPECT_FALSE(fs::exists(dir / "third"));
}

TEST(BadInputEvaluation, IcpSlamWithRelationsThatMatchNothingIsAnError) {
    TempDir dir;
    const std::string in = dir / "room.rawlog", rel = dir / "far.relations";
    kfd::test::writeRoomLog(in, 10);
    std::ofstream(rel) << "500 501 1 0 0 0 0 0\n";
    const std::string before = fileBytes(in);
    const Result r = run(KFD_ICP_SLAM_EXE, "-q " + q(kIcpConfig) + " " + q(in) + " -o " +
                                               q(dir / "out") + " --no-map --relations " + q(rel));
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.firstErrLine().rfind("kfd-icp-slam: no relation matched the trajectory", 0), 0u)
        << r.err;
    EXPECT_EQ(fileBytes(in), before);
    const Result neg = run(KFD_ICP_SLAM_EXE, "-q " + q(kIcpConfig) + " " + q(in) + " -o " +
                                                 q(dir / "out2") + " --max-dt -1");
    EXPECT_NE(neg.status, 0);
    EXPECT_NE(neg.err.find("tolerance must be finite and >= 0"), std::string::npos) << neg.err;
    EXPECT_FALSE(fs::exists(dir / "out2"));  // checked before anything is written
}

}  // namespace
