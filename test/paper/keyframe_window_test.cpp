// The paper's keyframe test (Sec. 3.1.4, Formula 3) on hand-made histograms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/paper/correlation.h"
#include "kfd/paper/keyframe_window.h"

namespace {

using kfd::KeyframeWindow;

KeyframeWindow window(std::size_t bins, std::size_t m, double p_pair) {
    return KeyframeWindow(KeyframeWindow::Params{bins, m, p_pair});
}

TEST(KeyframeWindow, AnEmptyWindowMakesEveryHistogramAKeyframe) {
    const auto w = window(4, 3, 0.9);
    const std::vector<double> h{1, 2, 3, 4};
    const auto v = w.compare(h.data());
    EXPECT_TRUE(v.keyframe);
    EXPECT_EQ(v.references, 0u);
    EXPECT_EQ(v.p_common, 0.0);
    EXPECT_EQ(v.p_threshold, 1.0);
}

TEST(KeyframeWindow, TheSameHistogramIsSimilarAndComparingChangesNothing) {
    auto w = window(4, 3, 0.9);
    const std::vector<double> h{1, 2, 3, 4};
    w.accept(h.data());
    const auto v = w.compare(h.data());
    EXPECT_FALSE(v.keyframe);
    EXPECT_DOUBLE_EQ(v.p_common, 1.0);
    EXPECT_DOUBLE_EQ(v.p_threshold, 0.9);
    EXPECT_EQ(w.size(), 1u);
}

TEST(KeyframeWindow, AnAntiCorrelatedHistogramIsAKeyframeNeverSimilar) {
    auto w = window(4, 2, 0.5);
    const std::vector<double> a{1, 2, 3, 4}, b{4, 3, 2, 1};
    w.accept(a.data());
    w.accept(a.data());
    const auto v = w.compare(b.data());  // two negative correlations, clamped to 0
    EXPECT_TRUE(v.keyframe);
    EXPECT_EQ(v.p_common, 0.0);
    EXPECT_EQ(v.min_similarity, 0.0);
}

TEST(KeyframeWindow, TheThresholdIsPPairToTheReferencesHeld) {
    auto w = window(4, 8, 0.9);
    const std::vector<double> h{1, 2, 3, 4};
    for (int i = 0; i < 3; ++i) w.accept(h.data());
    EXPECT_DOUBLE_EQ(w.compare(h.data()).p_threshold, std::pow(0.9, 3));
}

TEST(KeyframeWindow, AFullWindowEvictsTheOldestKeyframe) {
    auto w = window(4, 2, 0.99);
    const std::vector<double> old{4, 3, 2, 1}, a{1, 2, 3, 4}, b{1, 2, 3, 5};
    w.accept(old.data());
    w.accept(a.data());
    EXPECT_TRUE(w.compare(a.data()).keyframe);  // `old` is anti-correlated: P_common = 0
    w.accept(b.data());                         // evicts `old`
    EXPECT_EQ(w.size(), 2u);
    const auto v = w.compare(a.data());
    EXPECT_DOUBLE_EQ(v.p_common, kfd::similarity(a.data(), b.data(), 4));
    EXPECT_EQ(v.references, 2u);
}

TEST(KeyframeWindow, BadParametersNameTheirField) {
    const auto field = [](KeyframeWindow::Params p) {
        try {
            KeyframeWindow w(p);
        } catch (const kfd::ParameterError& e) {
            return e.field();
        }
        return std::string("none");
    };
    EXPECT_EQ(field({1, 3, 0.9}), "bins");
    EXPECT_EQ(field({4, 0, 0.9}), "window");
    EXPECT_EQ(field({4, 3, 0.0}), "p_pair");
    EXPECT_EQ(field({4, 3, 1.5}), "p_pair");
}

// The paper's selector (the keyframe stage's) without guards is exactly the window (Formula 3),
// over random histograms: the same verdicts, products and thresholds.
TEST(KeyframeWindow, ThePaperSelectorWithoutGuardsDecidesAsTheWindow) {
    kfd::KeyframeSelector::Params p;
    p.bins = 6;
    p.window = 3;
    p.p_pair = 0.97;
    p.max_consecutive_drops = 0;
    p.max_interval_s = 0;
    p.max_translation_m = 0;
    p.max_rotation_deg = 0;
    kfd::KeyframeSelector selector(p);
    auto w = window(6, 3, 0.97);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::vector<double> base{1, 2, 3, 2, 1, 4}, h(6);
    int keyframes = 0;
    for (int i = 0; i < 400; ++i) {
        if (i % 50 == 0) std::shuffle(base.begin(), base.end(), rng);
        for (std::size_t b = 0; b < h.size(); ++b) h[b] = base[b] + noise(rng);
        const auto v = w.compare(h.data());
        if (v.keyframe) w.accept(h.data());
        const auto d = selector.decide(h, i * 0.1, std::nullopt);
        ASSERT_EQ(d.keyframe, v.keyframe) << "scan " << i;
        ASSERT_EQ(d.p_common, v.p_common);
        ASSERT_EQ(d.p_threshold, v.p_threshold);
        ASSERT_EQ(d.references, v.references);
        keyframes += d.keyframe;
    }
    EXPECT_GT(keyframes, 8);  // both verdicts occur
    EXPECT_LT(keyframes, 392);
}

}  // namespace
