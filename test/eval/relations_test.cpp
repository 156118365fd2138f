// kfd/eval/relations.h: the Kümmerle et al. 2009 relations metric on hand-computed cases.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "kfd/eval/relations.h"

namespace {
constexpr double kDeg = 180.0 / M_PI;
}

TEST(Relations, PerfectEstimateHasZeroError) {
    kfd::Trajectory t{{1, {0, 0, 0}}, {2, {1, 1, 0.5}}, {3, {2, 0, -1.0}}};
    std::vector<kfd::Relation> rel{{1, 2, kfd::between(t[0].pose, t[1].pose)},
                                   {2, 3, kfd::between(t[1].pose, t[2].pose)}};
    const auto e = kfd::evaluateRelations(t, rel, 1e-3);
    EXPECT_EQ(e.used, 2u);
    EXPECT_EQ(e.unmatched, 0u);
    EXPECT_NEAR(e.trans_mean, 0.0, 1e-12);
    EXPECT_NEAR(e.rot_mean_deg, 0.0, 1e-9);
}

TEST(Relations, ComponentWiseErrorByHand) {
    // Estimate moves (1.1, 0) and turns 0.1 rad; ground truth says (1, 0), no turn.
    kfd::Trajectory t{{10, {0, 0, 0}}, {11, {1.1, 0, 0.1}}};
    std::vector<kfd::Relation> rel{{10, 11, {1.0, 0.0, 0.0}}};
    const auto e = kfd::evaluateRelations(t, rel, 1e-3);
    EXPECT_NEAR(e.trans_mean, 0.1, 1e-12);
    EXPECT_NEAR(e.rot_mean_deg, 0.1 * kDeg, 1e-9);
    EXPECT_NEAR(e.trans2_mean, 0.01, 1e-12);
    EXPECT_NEAR(e.trans_std, 0.0, 1e-12);
}

TEST(Relations, ErrorIsInTheFrameOfTheFirstPose) {
    // The same motion seen from a robot facing +y: (0, 1.1) in world = (1.1, 0) in its frame.
    kfd::Trajectory t{{10, {5, 5, M_PI / 2}}, {11, {5, 6.1, M_PI / 2}}};
    const auto e = kfd::evaluateRelations(t, {{10, 11, {1.0, 0.0, 0.0}}}, 1e-3);
    EXPECT_NEAR(e.trans_mean, 0.1, 1e-12);
    EXPECT_NEAR(e.rot_mean_deg, 0.0, 1e-9);
}

TEST(Relations, MeanAndPopulationStd) {
    // Translation errors 0.1 and 0.3: mean 0.2, population std 0.1; squares 0.01, 0.09.
    kfd::Trajectory t{{1, {0, 0, 0}}, {2, {1.1, 0, 0}}, {3, {2.4, 0, 0}}};
    std::vector<kfd::Relation> rel{{1, 2, {1, 0, 0}}, {2, 3, {1, 0, 0}}};
    const auto e = kfd::evaluateRelations(t, rel, 1e-3);
    EXPECT_NEAR(e.trans_mean, 0.2, 1e-12);
    EXPECT_NEAR(e.trans_std, 0.1, 1e-12);
    EXPECT_NEAR(e.trans2_mean, 0.05, 1e-12);
    EXPECT_NEAR(e.trans2_std, 0.04, 1e-12);
}

TEST(Relations, RotationErrorWrapsAroundPi) {
    kfd::Trajectory t{{1, {0, 0, 0}}, {2, {0, 0, M_PI - 0.05}}};
    const auto e = kfd::evaluateRelations(t, {{1, 2, {0, 0, -M_PI + 0.05}}}, 1e-3);
    EXPECT_NEAR(e.rot_mean_deg, 0.1 * kDeg, 1e-9);
}

TEST(Relations, UnmatchedStampsAreCountedNotDropped) {
    kfd::Trajectory t{{1, {}}, {2, {}}};
    std::vector<kfd::Relation> rel{{1, 2, {}}, {1, 2.5, {}}, {0.5, 2, {}}};
    const auto e = kfd::evaluateRelations(t, rel, 1e-3);
    EXPECT_EQ(e.used, 1u);
    EXPECT_EQ(e.unmatched, 2u);
    EXPECT_EQ(kfd::evaluateRelations(t, rel, 0.6).unmatched, 0u);
}

TEST(Relations, ReadsTheBenchmarkFormat) {
    const auto f = (std::filesystem::temp_directory_path() / "kfd_rel_test.relations").string();
    std::ofstream(f) << "976052905.167303 976052911.885496 -0.056990 -0.128430 0.000000 0.000000 "
                        "0.000000 -1.682210\n\n# comment\n1 2 3 4 0 0 0 0.5\n";
    const auto r = kfd::readRelations(f);
    ASSERT_EQ(r.size(), 2u);
    EXPECT_DOUBLE_EQ(r[0].t1, 976052905.167303);
    EXPECT_DOUBLE_EQ(r[0].delta.x, -0.056990);
    EXPECT_DOUBLE_EQ(r[0].delta.phi, -1.682210);
    EXPECT_DOUBLE_EQ(r[1].delta.y, 4.0);
    std::ofstream(f) << "1 2 3\n";
    EXPECT_THROW(kfd::readRelations(f), kfd::EvalError);
    std::filesystem::remove(f);
}

TEST(Relations, SplitByTimeSpanKeepsOrderAndTheBoundaryIsLocal) {
    std::vector<kfd::Relation> rel{{0, 5, {}}, {0, 10, {}}, {3, 14, {}}, {20, 19, {}}, {1, 40, {}}};
    const auto s = kfd::splitRelations(rel, 10.0);
    ASSERT_EQ(s.local.size(), 3u);  // 5 s, exactly 10 s, and |19 - 20| = 1 s
    EXPECT_EQ(s.local[1].t2, 10.0);
    EXPECT_EQ(s.local[2].t1, 20.0);
    ASSERT_EQ(s.far.size(), 2u);  // 11 s and 39 s
    EXPECT_EQ(s.far[0].t2, 14.0);
    EXPECT_EQ(kfd::splitRelations(rel, 0.0).local.size(), 0u);
    EXPECT_THROW(kfd::splitRelations(rel, -1.0), kfd::EvalError);
    EXPECT_THROW(kfd::splitRelations(rel, std::nan("")), kfd::EvalError);
}

TEST(KfdEvalCli, PrintsTheRelationsErrorAndFailsOnBadInput) {
    namespace fs = std::filesystem;
    const auto dir = fs::temp_directory_path() / "kfd_eval_cli";
    fs::create_directories(dir);
    kfd::writeTum((dir / "est.tum").string(), {{10, {0, 0, 0}}, {11, {1.1, 0, 0}}});
    std::ofstream(dir / "gt.relations") << "10 11 1 0 0 0 0 0\n10 12 1 0 0 0 0 0\n";
    const std::string out = (dir / "out.txt").string();
    auto run = [&](const std::string& args) {
        const std::string cmd =
            std::string("'") + KFD_EVAL_EXE + "' " + args + " > '" + out + "' 2>&1";
        const int st = std::system(cmd.c_str());
        return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    };
    ASSERT_EQ(
        run("'" + (dir / "est.tum").string() + "' -r '" + (dir / "gt.relations").string() + "'"),
        0);
    std::ifstream f(out);
    const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("1 used, 1 unmatched"), std::string::npos) << text;
    EXPECT_NE(text.find("trans abs  0.1000"), std::string::npos) << text;
    // --split-seconds: local (<= 1 s: the matched 10-11 relation) and long (10-12: unmatched,
    // so an error, not a perfect score).
    std::ofstream(dir / "two.relations") << "10 11 1 0 0 0 0 0\n10 11 1 0 0 0 0 0\n";
    ASSERT_EQ(run("'" + (dir / "est.tum").string() + "' -r '" + (dir / "two.relations").string() +
                  "' --split-seconds 1"),
              0);
    std::ifstream f2(out);
    const std::string split((std::istreambuf_iterator<char>(f2)), std::istreambuf_iterator<char>());
    EXPECT_NE(split.find("local (<= 1 s): 2 used, 0 unmatched: trans 0.1000"), std::string::npos)
        << split;
    EXPECT_NE(split.find("long  (>  1 s): no relation"), std::string::npos) << split;
    EXPECT_EQ(run("'" + (dir / "est.tum").string() + "' -r '" + (dir / "gt.relations").string() +
                  "' --split-seconds 1.5"),
              1);  // the long subset (10-12) matched nothing
    EXPECT_EQ(run("'" + (dir / "est.tum").string() + "' -r '" + (dir / "gt.relations").string() +
                  "' --split-seconds -2"),
              2);
    EXPECT_EQ(run("'" + (dir / "missing.tum").string() + "' -r '" +
                  (dir / "gt.relations").string() + "'"),
              1);
    EXPECT_EQ(run("'" + (dir / "est.tum").string() + "'"), 2);  // nothing to compare with
    fs::remove_all(dir);
}
