// The evaluation never reports a perfect score for nothing: zero matched poses or relations,
// negative tolerances, zero steps, zero quaternions and unparsable numbers are EvalErrors that
// name the parameter or the file and line.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "kfd/eval/ate.h"
#include "kfd/eval/relations.h"
#include "kfd/eval/trajectory.h"
#include "test_files.h"

namespace {

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_badeval_") {}
};

kfd::Trajectory line(double t0, int n) {
    kfd::Trajectory t;
    for (int i = 0; i < n; ++i) t.push_back({t0 + i, {1.0 * i, 0.0, 0.0}});
    return t;
}

// The EvalError's message and field for `f()`, or "<no error>".
template <class F>
std::pair<std::string, std::string> evalError(F&& f) {
    try {
        f();
    } catch (const kfd::EvalError& e) {
        return {e.what(), e.field()};
    }
    return {"<no error>", ""};
}

bool contains(const std::string& s, const std::string& part) {
    return s.find(part) != std::string::npos;
}

}  // namespace

TEST(EvalBadInput, RelationsWithNoMatchIsAnErrorNotAPerfectZero) {
    const auto traj = line(0.0, 10);
    const auto e = evalError([&] {
        kfd::evaluateRelations(traj, {{100.0, 101.0, {1, 0, 0}}}, 1e-3);
    });
    EXPECT_TRUE(contains(e.first, "no relation matched")) << e.first;
    EXPECT_TRUE(contains(evalError([&] {
                             kfd::evaluateRelations({}, {{0, 1, {}}}, 1e-3);
                         }).first,
                         "no relation matched"));
    EXPECT_TRUE(
        contains(evalError([&] { kfd::evaluateRelations(traj, {}, 1e-3); }).first, "no relations"));
}

TEST(EvalBadInput, NegativeOrNaNToleranceIsAnErrorNamingMaxDt) {
    const auto traj = line(0.0, 10);
    for (const double dt : {-1e-3, std::nan(""), std::numeric_limits<double>::infinity()}) {
        EXPECT_EQ(evalError([&] {
                      kfd::evaluateRelations(traj, {{0, 1, {1, 0, 0}}}, dt);
                  }).second,
                  "max_dt");
        EXPECT_EQ(evalError([&] { kfd::computeAte(traj, traj, dt); }).second, "max_dt");
        EXPECT_EQ(evalError([&] { kfd::computeRpe(traj, traj, 1.0, dt); }).second, "max_dt");
    }
}

TEST(EvalBadInput, AteWithNoOverlapIsAnError) {
    const auto e = evalError([&] { kfd::computeAte(line(0.0, 10), line(100.0, 10), 1e-3); });
    EXPECT_TRUE(contains(e.first, "0 of 10 matched")) << e.first;
    EXPECT_TRUE(
        contains(evalError([&] { kfd::computeAte({}, line(0.0, 3), 1e-3); }).first, "at least 2"));
}

TEST(EvalBadInput, RpeWithZeroOrNegativeStepOrNoPairIsAnError) {
    const auto traj = line(0.0, 10);
    for (const double d : {0.0, -1.0, std::nan("")})
        EXPECT_EQ(evalError([&] { kfd::computeRpe(traj, traj, d, 1e-3); }).second, "delta_s");
    EXPECT_TRUE(contains(evalError([&] { kfd::computeRpe(traj, traj, 100.0, 1e-3); }).first,
                         "no pose pair"));
    EXPECT_TRUE(
        contains(evalError([&] { kfd::computeRpe(line(100.0, 10), traj, 1.0, 1e-3); }).first,
                 "no pose pair"));
}

TEST(EvalBadInput, ZeroQuaternionNamesTheFileAndLine) {
    TempDir dir;
    const std::string f = dir / "gt.tum";
    std::ofstream(f) << "# t x y z qx qy qz qw\n1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 0\n";
    const auto e = evalError([&] { kfd::readTum(f); });
    EXPECT_EQ(e.first, f + ":3: the quaternion has norm 0");
    EXPECT_EQ(e.second, f + ":3");
}

TEST(EvalBadInput, AnUnnormalisedQuaternionGivesTheSameYaw) {
    TempDir dir;
    const std::string f = dir / "gt.tum";
    const double h = 0.3;  // yaw 0.6 rad, quaternion scaled by 5
    std::ofstream(f) << "1 0 0 0 0 0 " << 5 * std::sin(h) << " " << 5 * std::cos(h) << "\n";
    const auto t = kfd::readTum(f);
    ASSERT_EQ(t.size(), 1u);
    EXPECT_NEAR(t[0].pose.phi, 0.6, 1e-5);  // the file holds 6 significant digits
}

TEST(EvalBadInput, UnparsableOrNonFiniteNumbersNameTheFileAndLine) {
    TempDir dir;
    for (const char* bad : {"1 0 0 0 0 0 0 1abc", "1 0 0 0 0 0 0 nan", "1 inf 0 0 0 0 0 1",
                            "1 0 0 0 0 0 0 1e999", "1 0,5 0 0 0 0 0 1", "1 0 0 0 0 0 0"}) {
        const std::string f = dir / "est.tum";
        std::ofstream(f) << "0 0 0 0 0 0 0 1\n\n" << bad << "\n";
        const auto e = evalError([&] { kfd::readTum(f); });
        EXPECT_EQ(e.first.rfind(f + ":3: expected 't x y z qx qy qz qw'", 0), 0u)
            << bad << ": " << e.first;
        EXPECT_EQ(e.second, f + ":3") << bad;
    }
    const std::string r = dir / "gt.relations";
    std::ofstream(r) << "1 2 0.5 0 0 0 0 x\n";
    EXPECT_EQ(evalError([&] { kfd::readRelations(r); }).second, r + ":1");
}
