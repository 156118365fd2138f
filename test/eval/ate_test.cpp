// kfd/eval/ate.h: ATE with SE(2) alignment and RPE on synthetic trajectories.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "kfd/eval/ate.h"

namespace {

kfd::Trajectory squarePath(std::size_t n) {
    kfd::Trajectory t;
    for (std::size_t i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / static_cast<double>(n) * 4.0;
        const int side = static_cast<int>(s);
        const double f = s - side;
        const double xs[] = {f, 1, 1 - f, 0}, ys[] = {0, f, 1, 1 - f};
        t.push_back({0.1 * static_cast<double>(i), {3 * xs[side], 3 * ys[side], side * M_PI / 2}});
    }
    return t;
}

kfd::Trajectory moved(const kfd::Trajectory& t, const kfd::Pose2D& T) {
    kfd::Trajectory o = t;
    for (auto& p : o) p.pose = kfd::compose(T, p.pose);
    return o;
}

}  // namespace

TEST(Ate, RigidlyMovedEstimateHasZeroErrorAndTheTransformIsRecovered) {
    const auto gt = squarePath(200);
    const kfd::Pose2D T{2.0, -1.0, 0.8};
    const auto est = moved(gt, kfd::inverse(T));  // gt = T (+) est
    const auto a = kfd::computeAte(est, gt, 1e-3);
    EXPECT_EQ(a.matched, 200u);
    EXPECT_NEAR(a.rmse, 0.0, 1e-9);
    EXPECT_NEAR(a.alignment.x, T.x, 1e-9);
    EXPECT_NEAR(a.alignment.y, T.y, 1e-9);
    EXPECT_NEAR(a.alignment.phi, T.phi, 1e-9);
}

TEST(Ate, KnownOffsetsGiveKnownRmse) {
    // Errors of +-d alternating perpendicular to a straight line cancel in the alignment:
    // the RMSE is exactly d.
    kfd::Trajectory gt, est;
    for (int i = 0; i < 100; ++i) {
        gt.push_back({double(i), {0.1 * i, 0, 0}});
        est.push_back({double(i), {0.1 * i, (i % 2 ? 0.05 : -0.05), 0}});
    }
    const auto a = kfd::computeAte(est, gt, 1e-3);
    EXPECT_NEAR(a.rmse, 0.05, 1e-3);
    EXPECT_NEAR(a.max, 0.05, 2e-3);
}

TEST(Ate, UnmatchedStampsAreCounted) {
    const auto gt = squarePath(50);
    auto est = gt;
    est.push_back({1000.0, {}});
    const auto a = kfd::computeAte(est, gt, 1e-3);
    EXPECT_EQ(a.matched, 50u);
    EXPECT_EQ(a.unmatched, 1u);
    EXPECT_THROW(kfd::computeAte({{1000.0, {}}}, gt, 1e-3), kfd::EvalError);
}

TEST(Ate, AGroundTruthMatchingLessThanHalfTheEstimateIsAnErrorWithTheCounts) {
    const auto gt = squarePath(40);  // stamps 0 .. 3.9 s
    auto est = gt;
    for (int i = 0; i < 41; ++i) est.push_back({100.0 + i, {}});  // 40 of 81 match
    try {
        kfd::computeAte(est, gt, 1e-3);
        FAIL() << "no error";
    } catch (const kfd::EvalError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("only 40 of 81"), std::string::npos) << m;
        EXPECT_NE(m.find("41 unmatched"), std::string::npos) << m;
        EXPECT_NE(m.find("0.001 s"), std::string::npos) << m;
    }
    est.pop_back();  // 40 of 80: half is enough
    EXPECT_EQ(kfd::computeAte(est, gt, 1e-3).matched, 40u);
}

TEST(Rpe, PerfectAndRigidlyMovedEstimatesHaveZeroError) {
    const auto gt = squarePath(100);
    const auto r = kfd::computeRpe(moved(gt, {5, 5, 1}), gt, 1.0, 1e-3);
    EXPECT_GT(r.pairs, 80u);
    EXPECT_NEAR(r.trans_rmse, 0.0, 1e-9);
    EXPECT_NEAR(r.rot_rmse_deg, 0.0, 1e-9);
}

TEST(Rpe, ScaleErrorShowsUpPerStep) {
    // The estimate travels 10% farther: over 1 s steps along x of 1 m, the error is 0.1 m.
    // (Stamps 1/8 s apart are exact in binary, so every step spans exactly 1 s.)
    kfd::Trajectory gt, est;
    for (int i = 0; i <= 48; ++i) {
        gt.push_back({0.125 * i, {0.125 * i, 0, 0}});
        est.push_back({0.125 * i, {0.1375 * i, 0, 0}});
    }
    const auto r = kfd::computeRpe(est, gt, 1.0, 1e-3);
    EXPECT_NEAR(r.trans_rmse, 0.1, 1e-6);
    EXPECT_NEAR(r.rot_rmse_deg, 0.0, 1e-9);
}
