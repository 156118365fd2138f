#include "kfd/paper/window_helper.h"

#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace kfd {
namespace {

double power(double base, std::size_t n) {
    double r = 1.0;
    for (std::size_t i = 0; i < n; ++i) r *= base;
    return r;
}

TEST(WindowHelper, PaperFastSetting) {
    // 0.752 m/s at 40 Hz: dx = 1.88 cm, dx^2 = 3.5344 -> 18 < m*dx^2 < 30 for m = 6..8.
    const auto s = suggestWindow(0.752, 40.0, 0.985);
    EXPECT_NEAR(s.dx_cm, 1.88, 1e-12);
    EXPECT_EQ(s.m_min, 6u);
    EXPECT_EQ(s.m_max, 8u);
    EXPECT_EQ(s.m, 6u);  // the smallest allowed window
    EXPECT_TRUE(s.rule_satisfied);
    EXPECT_TRUE(s.note.empty()) << s.note;
    EXPECT_NEAR(s.p_threshold, power(0.985, 6), 1e-12);
}

TEST(WindowHelper, PaperSlowSetting) {
    // 0.575 m/s at 40 Hz: dx = 1.4375 cm, dx^2 = 2.0664 -> m = 9..14.
    const auto s = suggestWindow(0.575, 40.0, 0.985);
    EXPECT_NEAR(s.dx_cm, 1.4375, 1e-12);
    EXPECT_EQ(s.m_min, 9u);
    EXPECT_EQ(s.m_max, 14u);
    EXPECT_EQ(s.m, 9u);
    EXPECT_TRUE(s.rule_satisfied);
    EXPECT_NEAR(s.p_threshold, power(0.985, 9), 1e-12);
}

TEST(WindowHelper, PapersOwnPicksLieInTheAllowedRanges) {
    const auto fast = suggestWindow(0.752, 40.0, 0.985);
    EXPECT_LE(fast.m_min, 8u);
    EXPECT_GE(fast.m_max, 8u);
    const auto slow = suggestWindow(0.575, 40.0, 0.985);
    EXPECT_LE(slow.m_min, 9u);
    EXPECT_GE(slow.m_max, 9u);
}

TEST(WindowHelper, BoundsAreExclusive) {
    // dx = 1 cm: m*dx^2 = m, so 18 and 30 themselves are excluded -> 19..29.
    const auto s = suggestWindow(1.0, 100.0, 0.9);
    EXPECT_DOUBLE_EQ(s.dx_cm, 1.0);
    EXPECT_EQ(s.m_min, 19u);
    EXPECT_EQ(s.m_max, 29u);
    EXPECT_EQ(s.m, 19u);
    // dx = 1.5 cm: dx^2 = 2.25, 8 * 2.25 = 18 exactly is excluded -> 9..13.
    const auto t = suggestWindow(1.5, 100.0, 0.9);
    EXPECT_EQ(t.m_min, 9u);
    EXPECT_EQ(t.m_max, 13u);
}

TEST(WindowHelper, SlowScannerFallsBackToOneReference) {
    // A 5 Hz log at 0.5 m/s: dx = 10 cm, dx^2 = 100 > 30 for every m >= 1.
    const auto s = suggestWindow(0.5, 5.0, 0.985);
    EXPECT_NEAR(s.dx_cm, 10.0, 1e-12);
    EXPECT_EQ(s.m, 1u);
    EXPECT_FALSE(s.rule_satisfied);
    EXPECT_EQ(s.m_min, 0u);
    EXPECT_EQ(s.m_max, 0u);
    EXPECT_FALSE(s.note.empty());
    EXPECT_NEAR(s.p_threshold, 0.985, 1e-15);
}

TEST(WindowHelper, SingleReferenceWhenDxSquaredFitsAlone) {
    // dx = 5 cm at 0.25 m/s, 5 Hz: dx^2 = 25 lies in (18, 30) for m = 1 only.
    const auto s = suggestWindow(0.25, 5.0, 0.985);
    EXPECT_EQ(s.m_min, 1u);
    EXPECT_EQ(s.m_max, 1u);
    EXPECT_EQ(s.m, 1u);
    EXPECT_TRUE(s.rule_satisfied);
}

TEST(WindowHelper, NoIntegerFitsBetweenTheBounds) {
    // dx = 4 cm: dx^2 = 16, so m = 1 gives 16 (< 18) and m = 2 gives 32 (> 30).
    const auto s = suggestWindow(4.0, 100.0, 0.9);
    EXPECT_EQ(s.m_min, 0u);
    EXPECT_EQ(s.m_max, 0u);
    EXPECT_FALSE(s.rule_satisfied);
    EXPECT_FALSE(s.note.empty());
    EXPECT_TRUE(s.m == 1u || s.m == 2u) << s.m;
    EXPECT_NEAR(s.p_threshold, power(0.9, s.m), 1e-15);
}

TEST(WindowHelper, AlmostStillRobotIsCappedAtMaxWindow) {
    // 1.1 cm/s at 40 Hz: dx = 0.0275 cm, dx^2 = 0.00075625: Formula 5 asks for m >= 23802.
    WindowHelperParams p;
    p.max_window = 32;
    const auto s = suggestWindow(0.011, 40.0, 0.999, p);
    EXPECT_EQ(s.m, 32u);
    EXPECT_FALSE(s.rule_satisfied);
    EXPECT_EQ(s.m_min, 23802u);
    EXPECT_EQ(s.m_max, 39669u);
    EXPECT_FALSE(s.note.empty());
    EXPECT_NEAR(s.p_threshold, power(0.999, 32), 1e-12);
}

TEST(WindowHelper, CustomBounds) {
    WindowHelperParams p;
    p.lower = 10.0;
    p.upper = 20.0;
    // dx = 1 cm: 10 < m < 20 -> 11..19.
    const auto s = suggestWindow(1.0, 100.0, 0.9, p);
    EXPECT_EQ(s.m_min, 11u);
    EXPECT_EQ(s.m_max, 19u);
    EXPECT_EQ(s.m, 11u);
}

TEST(WindowHelper, PThresholdIsPPairToTheM) {
    for (const double p_pair : {1.0, 0.99, 0.985, 0.9, 0.5}) {
        const auto s = suggestWindow(0.575, 40.0, p_pair);
        EXPECT_NEAR(s.p_threshold, power(p_pair, s.m), 1e-14) << p_pair;
    }
    EXPECT_EQ(suggestWindow(0.575, 40.0, 1.0).p_threshold, 1.0);
}

TEST(WindowHelper, RejectsInvalidInput) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    EXPECT_THROW(suggestWindow(0.0, 40.0, 0.985), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(-0.5, 40.0, 0.985), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(nan, 40.0, 0.985), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(inf, 40.0, 0.985), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(0.5, 0.0, 0.985), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(0.5, -40.0, 0.985), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(0.5, nan, 0.985), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(0.5, 40.0, 0.0), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(0.5, 40.0, 1.01), kfd::ParameterError);
    EXPECT_THROW(suggestWindow(0.5, 40.0, nan), kfd::ParameterError);
    WindowHelperParams p;
    p.lower = 30.0;
    p.upper = 18.0;
    EXPECT_THROW(suggestWindow(0.5, 40.0, 0.985, p), kfd::ParameterError);
    p = WindowHelperParams{};
    p.max_window = 0;
    EXPECT_THROW(suggestWindow(0.5, 40.0, 0.985, p), kfd::ParameterError);
}

}  // namespace
}  // namespace kfd
