// Uniform decimation (baseline): which scans it keeps, on counts alone.
#include "kfd/baselines/decimator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "kfd/baselines/decimate_stage.h"
#include "kfd/baselines/stages.h"
#include "kfd/pipeline/stage_registry.h"

namespace {

// The kept pattern of the first n scans, e.g. "x..x..x".
std::string pattern(double keep, int n) {
    kfd::Decimator d(kfd::Decimator::Params{keep});
    std::string s;
    for (int i = 0; i < n; ++i) s += d.keep() ? 'x' : '.';
    return s;
}

TEST(Decimator, KeepsEveryKthScanStartingWithTheFirst) {
    EXPECT_EQ(pattern(1.0, 5), "xxxxx");
    EXPECT_EQ(pattern(0.5, 6), "x.x.x.");
    EXPECT_EQ(pattern(1.0 / 3.0, 7), "x..x..x");
    EXPECT_EQ(pattern(0.25, 9), "x...x...x");
}

TEST(Decimator, AFractionalShareIsKeptExactlyAndEvenly) {
    kfd::Decimator d(kfd::Decimator::Params{0.7});
    int kept = 0, longest_gap = 0, gap = 0;
    for (int i = 0; i < 1000; ++i) {
        if (d.keep()) {
            ++kept;
            gap = 0;
        } else {
            longest_gap = std::max(longest_gap, ++gap);
        }
    }
    EXPECT_EQ(kept, 700);
    EXPECT_EQ(longest_gap, 1);  // never two drops in a row at 70 %
    // n * 0.3 crosses an integer at n = 4, 7, 10 (10 * 0.3 is 2.9999... in binary: still kept)
    EXPECT_EQ(pattern(0.3, 11), "x...x..x..x");
}

TEST(Decimator, ResetStartsThePatternAgain) {
    kfd::Decimator d(kfd::Decimator::Params{0.5});
    EXPECT_TRUE(d.keep());
    EXPECT_FALSE(d.keep());
    d.reset();
    EXPECT_TRUE(d.keep());
}

TEST(Decimator, AShareOutsideZeroToOneIsAParameterError) {
    for (double bad : {0.0, -0.5, 1.5, std::nan("")}) {
        SCOPED_TRACE(bad);
        EXPECT_THROW(kfd::Decimator(kfd::Decimator::Params{bad}), kfd::ParameterError);
    }
}

TEST(DecimateStage, IsRegisteredByNameWithItsKey) {
    kfd::StageRegistry reg;
    kfd::registerBaselineStages(reg);
    const auto* info = reg.find("decimate");
    ASSERT_NE(info, nullptr);
    ASSERT_EQ(info->keys.size(), 1u);
    EXPECT_EQ(info->keys[0].name, "decimate_keep");
}

}  // namespace
