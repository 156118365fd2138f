// kfd::ScanRateMeter (kfd/algorithms/scan_rate.h): the mean rate over the whole log and the median
// interval, on hand-made stamps with gaps.
#include "kfd/algorithms/scan_rate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

kfd::ScanRate rateOf(const std::vector<double>& stamps) {
    kfd::ScanRateMeter m;
    for (double t : stamps) m.add(t);
    return m.result();
}

}  // namespace

TEST(ScanRate, EvenStampsGiveTheRateBothWays) {
    std::vector<double> t;
    for (int k = 0; k <= 20; ++k) t.push_back(100.0 + 0.2 * k);  // 5 Hz for 4 s
    const auto r = rateOf(t);
    EXPECT_EQ(r.stamps, 21u);
    EXPECT_NEAR(r.span_s, 4.0, 1e-9);
    EXPECT_NEAR(r.mean_hz, 5.0, 1e-9);
    EXPECT_NEAR(r.median_interval_s, 0.2, 1e-6);
}

// A log at 10 Hz with two 2 s gaps: the mean over the log is lower than 1 / median interval,
// and the first scans alone (before the gaps) would say 10 Hz.
TEST(ScanRate, GapsLowerTheMeanNotTheMedianInterval) {
    std::vector<double> t;
    double now = 0.0;
    for (int part = 0; part < 3; ++part) {
        for (int k = 0; k < 30; ++k) {
            t.push_back(now);
            now += 0.1;
        }
        now += 2.0;  // the gap
    }
    const auto r = rateOf(t);
    const double span = t.back() - t.front();
    EXPECT_EQ(r.stamps, 90u);
    EXPECT_NEAR(r.span_s, span, 1e-9);
    EXPECT_NEAR(r.mean_hz, 89.0 / span, 1e-9);  // 89 intervals over 12.9 s: 6.9 Hz
    EXPECT_LT(r.mean_hz, 7.0);
    EXPECT_NEAR(r.median_interval_s, 0.1, 1e-6);
}

TEST(ScanRate, BadAndRepeatedStampsAreNotIntervals) {
    const auto r = rateOf({1.0, std::nan(""), 1.5, 1.5, 2.0, 1.9, 2.5, INFINITY});
    EXPECT_EQ(r.stamps, 6u);  // the two non-finite ones ignored
    EXPECT_NEAR(r.span_s, 1.5, 1e-9);
    EXPECT_NEAR(r.mean_hz, 5.0 / 1.5, 1e-9);
    // Positive intervals: 0.5, 0.5, 0.6 (1.9 -> 2.5): the median is 0.5.
    EXPECT_NEAR(r.median_interval_s, 0.5, 1e-6);
    EXPECT_EQ(rateOf({}).mean_hz, 0.0);
    EXPECT_EQ(rateOf({3.0}).mean_hz, 0.0);
    EXPECT_EQ(rateOf({3.0}).median_interval_s, 0.0);
}
