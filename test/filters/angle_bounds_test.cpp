// The angle_bounds stage (laser_filters' angular bounds) on hand-made scans.
#include "kfd/filters/angle_bounds.h"

#include <cmath>

#include <gtest/gtest.h>

#include "kfd/pipeline/stage_registry.h"
#include "test_scans.h"

namespace kfd {
namespace {

AngleBounds bounds(double lo, double hi, bool inside = false) {
    AngleBounds::Params p;
    p.lower_deg = lo;
    p.upper_deg = hi;
    p.remove_inside = inside;
    return AngleBounds(p);
}

TEST(AngleBounds, BeamsOutsideTheBoundsAreRemovedAndTheBeamCountKept) {
    Scan s = test::arc(181, kPi, 2.0);  // -90 .. 90 deg, one beam per degree
    const auto r = bounds(-45.5, 30.5).filter(s);
    EXPECT_EQ(s.size(), 181u);
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.points_removed, 181u - 76u);  // -45 .. 30 deg stay (bounds half a beam wider)
    EXPECT_EQ(s.valid[44], 0);                // -46 deg
    EXPECT_EQ(s.valid[45], 1);                // -45 deg
    EXPECT_EQ(s.valid[120], 1);               // 30 deg
    EXPECT_EQ(s.valid[121], 0);               // 31 deg
}

TEST(AngleBounds, RemoveInsideCutsOutAMountThatBlocksTheView) {
    Scan s = test::arc(181, kPi, 2.0);
    const auto r = bounds(-10.5, 10.5, true).filter(s);
    EXPECT_EQ(r.points_removed, 21u);
    EXPECT_EQ(s.valid[90], 0);
    EXPECT_EQ(s.valid[79], 1);
}

TEST(AngleBounds, AngleFollowsTheScanDirectionNotTheBeamIndex) {
    Scan s = test::makeScan(std::vector<float>(181, 2.0f), kPi, false);  // left to right
    bounds(-0.5, 90.5).filter(s);
    EXPECT_EQ(s.valid[0], 1);    // +90 deg (beam 0 points left when scanning left to right)
    EXPECT_EQ(s.valid[180], 0);  // -90 deg
}

TEST(AngleBounds, AFullCircleScanWrapsPast180Degrees) {
    Scan s = test::circle(360, 2.0);  // -180 .. ~179 deg
    const auto r = bounds(-180.0, 180.0).filter(s);
    EXPECT_EQ(r.points_removed, 0u);
}

TEST(AngleBounds, InvalidBeamsAreNotCounted) {
    Scan s = test::arc(181, kPi, 2.0);
    test::invalidate(s, 0, 9);
    const auto r = bounds(-0.5, 90.5).filter(s);
    EXPECT_EQ(r.points_in, 171u);
    EXPECT_EQ(r.points_removed, 80u);  // -80 .. -1 deg
}

TEST(AngleBounds, BoundsOutOfOrderAreAParameterError) {
    EXPECT_THROW(bounds(30.0, -30.0), ParameterError);
    EXPECT_THROW(bounds(-200.0, 0.0), ParameterError);
}

TEST(AngleBoundsStage, KeysReachTheParamsAndCountRemovals) {
    StageRegistry r;
    r.add<AngleBoundsStage>();
    const StageInfo* info = r.find("angle_bounds");
    ASSERT_NE(info, nullptr);
    auto params = info->defaults();
    for (const auto& k : info->keys) {
        if (k.name == "angle_lower_deg") k.set(params->data(), "-45.5");
        if (k.name == "angle_upper_deg") k.set(params->data(), "45.5");
    }
    auto stage = info->create(*params);
    Scan s = test::arc(181, kPi, 2.0);
    StageReport rep;
    EXPECT_TRUE(stage->process(s, rep, ScanReport{}));
    EXPECT_EQ(rep.points_removed, 90u);
    EXPECT_FALSE(rep.noise);
    EXPECT_EQ(info->columns.at(0).cell(rep), "90");
    for (const auto& k : info->keys)
        if (k.name == "angle_upper_deg") {
            EXPECT_THROW(k.set(params->data(), "181"), ParameterError);
        }
}

}  // namespace
}  // namespace kfd
