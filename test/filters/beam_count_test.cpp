// The beam_count stage (a fixed beam count for a driver whose count varies) on hand-made scans.
#include "kfd/filters/beam_count.h"

#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "kfd/filters/stages.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/pipeline/stage_registry.h"
#include "test_scans.h"

namespace kfd {
namespace {

BeamCountResampler::Result resample(Scan& s, std::size_t beams, double max_jump = 0.05) {
    BeamCountResampler::Params p;
    p.max_jump = max_jump;
    Scan buffer;
    return BeamCountResampler(p).resample(s, beams, buffer);
}

TEST(BeamCount, UpsamplingAnArcKeepsItsRangeApertureAndDirection) {
    Scan s = test::arc(181, kPi, 2.0);
    const auto r = resample(s, 361);
    EXPECT_EQ(s.size(), 361u);
    EXPECT_EQ(s.valid.size(), 361u);
    EXPECT_EQ(s.geometry.beams, 361u);
    EXPECT_DOUBLE_EQ(s.geometry.aperture, kPi);
    EXPECT_TRUE(s.geometry.right_to_left);
    EXPECT_EQ(r.beams_in, 181u);
    EXPECT_EQ(r.points_out, 361u);
    EXPECT_EQ(r.points_removed, 0u);
    EXPECT_EQ(r.resampled, 1u);
    for (float v : s.range) EXPECT_FLOAT_EQ(v, 2.0f);
}

TEST(BeamCount, ARangeBetweenTwoBeamsOfOneSurfaceIsInterpolated) {
    Scan s = test::makeScan({2.0f, 2.1f, 2.2f}, kPi);
    resample(s, 5);
    EXPECT_NEAR(s.range[1], 2.05f, 1e-6);
    EXPECT_NEAR(s.range[3], 2.15f, 1e-6);
    EXPECT_FLOAT_EQ(s.range[4], 2.2f);
}

TEST(BeamCount, NoPointIsMadeUpBetweenANearAndAFarSurface) {
    Scan s = test::makeScan({1.0f, 1.0f, 5.0f, 5.0f}, kPi);
    resample(s, 7);  // output beam 3 lies halfway between input beams 1 (1 m) and 2 (5 m)
    for (float v : s.range) EXPECT_TRUE(v == 1.0f || v == 5.0f) << v;
}

TEST(BeamCount, AGapStaysAGap) {
    Scan s = test::arc(11, kPi, 3.0);
    test::invalidate(s, 4, 6);
    const auto r = resample(s, 21);
    // Input beams 4..6 lie at output positions 8..12; their neighbours 7 and 13 are half-way
    // to a valid beam and take the nearer one, i.e. the valid side only when it is nearer.
    for (std::size_t j = 8; j <= 12; ++j) EXPECT_EQ(s.valid[j], 0) << j;
    EXPECT_EQ(s.valid[6], 1);
    EXPECT_EQ(s.valid[14], 1);
    EXPECT_EQ(r.points_in, 8u);
    EXPECT_EQ(r.points_out, s.countValid());
}

TEST(BeamCount, DownsamplingKeepsTheEdgeBeams) {
    Scan s = test::makeScan({1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f}, kPi);
    resample(s, 4, 1.0);  // positions 0, 2, 4, 6: on input beams
    ASSERT_EQ(s.size(), 4u);
    EXPECT_FLOAT_EQ(s.range[0], 1.0f);
    EXPECT_FLOAT_EQ(s.range[1], 3.0f);
    EXPECT_FLOAT_EQ(s.range[3], 7.0f);
}

TEST(BeamCount, AScanThatAlreadyHasTheCountIsLeftUntouched) {
    Scan s = test::flatWall(181, 2.0, 3.0);
    test::invalidate(s, 10, 20);
    const Scan before = s;
    const auto r = resample(s, s.size());
    EXPECT_EQ(r.resampled, 0u);
    EXPECT_EQ(s.range, before.range);
    EXPECT_EQ(s.valid, before.valid);
}

TEST(BeamCount, IntensitiesFollowTheirBeams) {
    Scan s = test::makeScan({2.0f, 2.0f, 9.0f}, kPi);
    s.intensity = {100.0f, 200.0f, 50.0f};
    resample(s, 5);
    ASSERT_EQ(s.intensity.size(), 5u);
    EXPECT_FLOAT_EQ(s.intensity[1], 150.0f);  // interpolated on one surface
    EXPECT_TRUE(s.intensity[3] == 200.0f || s.intensity[3] == 50.0f);  // nearer beam's own
}

TEST(BeamCount, BadParametersAreRejected) {
    BeamCountResampler::Params p;
    p.beams = 1;
    EXPECT_THROW(BeamCountResampler{p}, ParameterError);
    p.beams = kMaxScanBeams + 1;
    EXPECT_THROW(BeamCountResampler{p}, ParameterError);
    p.beams = 0;
    p.max_jump = -0.1;
    EXPECT_THROW(BeamCountResampler{p}, ParameterError);
}

// A pipeline of beam_count and a stage that records the geometry it sees.
struct GeometrySpy : Stage {
    std::size_t* beams;
    explicit GeometrySpy(std::size_t* b) : beams(b) {}
    const char* name() const override { return "spy"; }
    bool process(Scan& scan, StageReport&, const ScanReport&) override {
        *beams = scan.size();
        EXPECT_EQ(scan.geometry.beams, scan.size());
        EXPECT_EQ(scan.valid.size(), scan.size());
        return true;
    }
};

TEST(BeamCount, ADriverWhoseCountVariesGivesTheFirstScansCountByDefault) {
    const StageRegistry registry = makeStageRegistry({registerFilterStages});
    Pipeline::Params params;
    params.stages = {"beam_count"};
    Pipeline pipeline(params, registry);
    std::size_t seen = 0;
    pipeline.add(std::make_unique<GeometrySpy>(&seen));
    for (std::size_t n : {360u, 359u, 361u, 357u, 360u}) {
        Scan s = test::circle(n, 2.0);
        const ScanGeometry out = pipeline.outputGeometry(s.geometry);
        pipeline.process(s);
        EXPECT_EQ(seen, 360u) << n;
        EXPECT_EQ(out.beams, 360u) << n;
    }
    pipeline.reset();  // the learned count describes the output stream: kept
    Scan s = test::circle(350, 2.0);
    pipeline.process(s);
    EXPECT_EQ(seen, 360u);
}

TEST(BeamCount, AConfiguredCountIsKnownBeforeTheFirstScan) {
    BeamCountStage::Params p;
    p.beams = 720;
    const BeamCountStage stage(p);
    EXPECT_EQ(stage.outputGeometry(test::geometry(360, kPi)).beams, 720u);
}

}  // namespace
}  // namespace kfd
