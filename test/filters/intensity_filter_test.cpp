// The intensity stage (laser_filters' intensity filter) on hand-made scans.
#include "kfd/filters/intensity_filter.h"

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

IntensityFilter thresholds(double lo, double hi) {
    IntensityFilter::Params p;
    p.lower = lo;
    p.upper = hi;
    return IntensityFilter(p);
}

TEST(IntensityFilter, WeakAndGlaringReturnsAreRemoved) {
    Scan s = test::arc(10, kPi, 2.0);
    s.intensity = {100, 100, 5, 100, 100, 9000, 100, 100, 100, 10};
    const auto r = thresholds(10, 5000).filter(s);
    EXPECT_EQ(r.points_removed, 2u);
    EXPECT_EQ(s.valid[2], 0);  // 5 < 10
    EXPECT_EQ(s.valid[5], 0);  // 9000 > 5000
    EXPECT_EQ(s.valid[9], 1);  // 10: on the bound, kept
    EXPECT_EQ(r.no_intensity, 0u);
}

TEST(IntensityFilter, AScanWithoutIntensitiesIsLeftAsItIsAndCounted) {
    Scan s = test::arc(10, kPi, 2.0);
    const auto r = thresholds(10, 5000).filter(s);
    EXPECT_EQ(r.points_removed, 0u);
    EXPECT_EQ(r.no_intensity, 1u);
    EXPECT_EQ(r.points_in, 10u);
    s.intensity = {1, 2};  // not one per beam: the same
    EXPECT_EQ(thresholds(10, 5000).filter(s).no_intensity, 1u);
}

TEST(IntensityFilter, InvalidBeamsAreLeftAlone) {
    Scan s = test::arc(4, kPi, 2.0);
    s.intensity = {0, 0, 100, 100};
    test::invalidate(s, 0, 0);
    const auto r = thresholds(10, 5000).filter(s);
    EXPECT_EQ(r.points_in, 3u);
    EXPECT_EQ(r.points_removed, 1u);
}

TEST(IntensityFilter, LowerAboveUpperIsAParameterError) {
    EXPECT_THROW(thresholds(10, 5), ParameterError);
}

}  // namespace
}  // namespace kfd
