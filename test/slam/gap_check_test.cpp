// The gap check: the goodness a correction across dropped scans must reach.
#include "kfd/slam/gap_check.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

TEST(GapCheck, ConfigurationMinimumUntilEnoughCorrections) {
    kfd::GapCheck g(0.4);
    EXPECT_DOUBLE_EQ(g.minimum(), 0.4);
    for (int i = 0; i < 7; ++i) g.accepted(0.9);
    EXPECT_DOUBLE_EQ(g.minimum(), 0.4);  // 7 < min_recent
    g.accepted(0.9);
    EXPECT_DOUBLE_EQ(g.minimum(), 0.75 * 0.9);
}

TEST(GapCheck, NeverBelowTheConfigurationMinimum) {
    kfd::GapCheck g(0.4);
    for (int i = 0; i < 20; ++i) g.accepted(0.45);  // a log where ICP matches little
    EXPECT_DOUBLE_EQ(g.minimum(), 0.4);
}

TEST(GapCheck, FollowsTheMedianNotTheOutliers) {
    kfd::GapCheck g(0.4);
    for (int i = 0; i < 9; ++i) g.accepted(0.8);
    for (int i = 0; i < 4; ++i) g.accepted(0.41);  // a few poor matches
    EXPECT_DOUBLE_EQ(g.minimum(), 0.75 * 0.8);
}

TEST(GapCheck, ForgetsCorrectionsOlderThanTheWindow) {
    kfd::GapCheck::Params p;
    p.recent = 10;
    kfd::GapCheck g(0.1, p);
    for (int i = 0; i < 10; ++i) g.accepted(0.9);
    for (int i = 0; i < 10; ++i) g.accepted(0.6);  // the environment changed
    EXPECT_DOUBLE_EQ(g.minimum(), 0.75 * 0.6);
}

TEST(GapCheck, MatchesAPlainMedianOverRandomInputs) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.05);
    for (int trial = 0; trial < 50; ++trial) {
        kfd::GapCheck::Params p;
        p.recent = 1 + rng() % 80;
        p.min_recent = 1;
        kfd::GapCheck g(0.2, p);
        std::vector<double> all;
        const int n = 1 + static_cast<int>(rng() % 200);
        for (int i = 0; i < n; ++i) {
            all.push_back(u(rng));
            g.accepted(all.back());
        }
        std::vector<double> last(
            all.end() - static_cast<std::ptrdiff_t>(std::min<std::size_t>(p.recent, all.size())),
            all.end());
        std::sort(last.begin(), last.end());
        const double median = last[last.size() / 2];  // the upper median, as documented
        EXPECT_DOUBLE_EQ(g.minimum(), std::max(0.2, 0.75 * median)) << trial;
    }
}
