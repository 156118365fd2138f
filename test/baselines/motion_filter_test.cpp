#include "kfd/baselines/motion_filter.h"

#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "baselines/all_stages.h"
#include "kfd/pipeline/pipeline.h"
#include "test_scans.h"

namespace kfd {
namespace {

using test::kInf;
using test::kNaN;

MotionFilter::Params params(double distance_m, double angle_deg, double interval_s) {
    MotionFilter::Params p;
    p.max_distance_m = distance_m;
    p.max_angle_deg = angle_deg;
    p.max_interval_s = interval_s;
    return p;
}

std::optional<Pose2D> pose(double x, double y, double phi_deg) {
    return Pose2D{x, y, test::deg2rad(phi_deg)};
}

TEST(MotionFilter, DefaultParams) {
    const MotionFilter f;
    EXPECT_EQ(f.params().max_distance_m, 0.2);
    EXPECT_EQ(f.params().max_angle_deg, 10.0);
    EXPECT_EQ(f.params().max_interval_s, 0.0);
    const MotionFilter g(params(1.5, 30.0, 4.0));
    EXPECT_EQ(g.params().max_distance_m, 1.5);
    EXPECT_EQ(g.params().max_angle_deg, 30.0);
    EXPECT_EQ(g.params().max_interval_s, 4.0);
}

TEST(MotionFilter, FirstScanIsKept) {
    // With every test off only the first scan can pass: it is kept for being the first.
    MotionFilter f(params(0.0, 0.0, 0.0));
    EXPECT_TRUE(f.keep(0.0, pose(1.0, 2.0, 30.0)));
    EXPECT_FALSE(f.keep(1.0, pose(1.0, 2.0, 30.0)));
    // Whatever its pose, and without a timestamp.
    MotionFilter g;
    EXPECT_TRUE(g.keep(kNaN, pose(-50.0, 7.0, -170.0)));
    EXPECT_FALSE(g.keep(kNaN, pose(-50.0, 7.0, -170.0)));
}

TEST(MotionFilter, NoMotionIsDropped) {
    MotionFilter f;  // defaults: 0.2 m, 10 deg, interval off
    ASSERT_TRUE(f.keep(0.0, pose(1.0, 2.0, 30.0)));
    for (int k = 1; k <= 50; ++k) EXPECT_FALSE(f.keep(0.1 * k, pose(1.0, 2.0, 30.0))) << k;
    // Motion below both thresholds is no motion either.
    EXPECT_FALSE(f.keep(6.0, pose(1.1, 2.1, 35.0)));
    EXPECT_FALSE(f.keep(7.0, pose(0.9, 1.9, 25.0)));
}

TEST(MotionFilter, LinearMotion) {
    // Steps of 1/16 m (exact in binary) against 0.25 m: distance is measured from the last
    // kept scan, not from the last scan seen, and reaching the threshold exactly is enough.
    MotionFilter f(params(0.25, 0.0, 0.0));
    std::vector<bool> kept;
    for (int k = 0; k <= 12; ++k) kept.push_back(f.keep(kNaN, pose(2.0 + 0.0625 * k, -1.0, 45.0)));
    EXPECT_EQ(kept, (std::vector<bool>{true, false, false, false, true, false, false, false, true,
                                       false, false, false, true}));

    // Euclidean distance: a diagonal move is kept although each coordinate moved < 0.25 m.
    MotionFilter g(params(0.25, 0.0, 0.0));
    ASSERT_TRUE(g.keep(kNaN, pose(0.0, 0.0, 0.0)));
    EXPECT_FALSE(g.keep(kNaN, pose(0.17, 0.17, 0.0)));  // 0.240 m
    EXPECT_TRUE(g.keep(kNaN, pose(0.18, 0.18, 0.0)));   // 0.255 m

    // Moving backwards or sideways counts the same.
    MotionFilter h(params(0.25, 0.0, 0.0));
    ASSERT_TRUE(h.keep(kNaN, pose(0.0, 0.0, 90.0)));
    EXPECT_FALSE(h.keep(kNaN, pose(-0.2, 0.0, 90.0)));
    EXPECT_TRUE(h.keep(kNaN, pose(-0.3, 0.0, 90.0)));
    EXPECT_FALSE(h.keep(kNaN, pose(-0.3, -0.2, 90.0)));
    EXPECT_TRUE(h.keep(kNaN, pose(-0.3, -0.3, 90.0)));
}

TEST(MotionFilter, RotationInPlace) {
    // Turning on the spot at 3 deg per scan against 10 deg: every fourth scan (12 deg) is kept.
    for (const double sign : {1.0, -1.0}) {
        MotionFilter f(params(0.2, 10.0, 0.0));
        std::vector<bool> kept;
        for (int k = 0; k <= 12; ++k) kept.push_back(f.keep(kNaN, pose(2.0, 3.0, sign * 3.0 * k)));
        EXPECT_EQ(kept, (std::vector<bool>{true, false, false, false, true, false, false, false,
                                           true, false, false, false, true}))
            << "sign " << sign;
    }
    MotionFilter f(params(0.2, 10.0, 0.0));
    ASSERT_TRUE(f.keep(kNaN, pose(0.0, 0.0, 40.0)));
    EXPECT_FALSE(f.keep(kNaN, pose(0.0, 0.0, 49.9)));
    EXPECT_TRUE(f.keep(kNaN, pose(0.0, 0.0, 50.1)));
    EXPECT_FALSE(f.keep(kNaN, pose(0.0, 0.0, 40.2)));
    EXPECT_TRUE(f.keep(kNaN, pose(0.0, 0.0, 39.9)));

    // Turning exactly the threshold is enough ("at least"), either way round.
    ASSERT_EQ(test::deg2rad(10.0) * 180.0 / kPi, 10.0);  // 10 deg survives the round trip
    MotionFilter g(params(0.0, 10.0, 0.0));
    ASSERT_TRUE(g.keep(kNaN, pose(0.0, 0.0, 0.0)));
    EXPECT_TRUE(g.keep(kNaN, pose(0.0, 0.0, 10.0)));
    EXPECT_TRUE(g.keep(kNaN, pose(0.0, 0.0, 0.0)));
}

TEST(MotionFilter, IntervalGuard) {
    MotionFilter f(params(0.2, 10.0, 2.0));
    const auto p = pose(1.0, 1.0, 0.0);
    EXPECT_TRUE(f.keep(10.0, p));
    EXPECT_FALSE(f.keep(11.0, p));
    EXPECT_FALSE(f.keep(11.99, p));
    EXPECT_TRUE(f.keep(12.0, p));  // exactly T after the last kept scan
    // Measured from the new reference.
    EXPECT_FALSE(f.keep(13.5, p));
    EXPECT_TRUE(f.keep(14.0, p));
    // An unknown timestamp cannot trigger the interval test.
    EXPECT_FALSE(f.keep(kNaN, p));
    EXPECT_TRUE(f.keep(100.0, p));
    // A scan kept for its motion is the new time reference too.
    EXPECT_TRUE(f.keep(101.0, pose(1.5, 1.0, 0.0)));
    EXPECT_FALSE(f.keep(102.5, pose(1.5, 1.0, 0.0)));  // 1.5 s after the motion keyframe
    EXPECT_TRUE(f.keep(103.0, pose(1.5, 1.0, 0.0)));
}

TEST(MotionFilter, IntervalIgnoresUnknownReferenceTime) {
    // A kept reference scan without a timestamp leaves the interval test without a reference
    // (as KeyframeSelector's MaxIntervalIgnoresUnknownTimestamps): neither 0.0 nor a stamp
    // from before reset() may stand in for it.
    MotionFilter f(params(0.0, 0.0, 5.0));
    const auto p = pose(0.0, 0.0, 0.0);
    EXPECT_TRUE(f.keep(kNaN, p));
    EXPECT_FALSE(f.keep(1.7e9, p));
    EXPECT_FALSE(f.keep(1.7e9 + 10.0, p));

    MotionFilter g(params(0.0, 0.0, 5.0));
    EXPECT_TRUE(g.keep(100.0, p));
    g.reset();
    EXPECT_TRUE(g.keep(kNaN, p));  // first after reset, time unknown
    EXPECT_FALSE(g.keep(105.0, p));
    EXPECT_FALSE(g.keep(200.0, p));
}

TEST(MotionFilter, EachTestOffAtZero) {
    {  // distance off: a 100 m jump is no reason; rotation and time still are
        MotionFilter f(params(0.0, 10.0, 2.0));
        ASSERT_TRUE(f.keep(0.0, pose(0.0, 0.0, 0.0)));
        EXPECT_FALSE(f.keep(0.5, pose(100.0, -40.0, 0.0)));
        EXPECT_TRUE(f.keep(1.0, pose(100.0, -40.0, 15.0)));
        EXPECT_FALSE(f.keep(2.0, pose(0.0, 0.0, 15.0)));
        EXPECT_TRUE(f.keep(3.0, pose(0.0, 0.0, 15.0)));
    }
    {  // angle off: half a turn is no reason; distance and time still are
        MotionFilter f(params(0.2, 0.0, 2.0));
        ASSERT_TRUE(f.keep(0.0, pose(0.0, 0.0, 0.0)));
        EXPECT_FALSE(f.keep(0.5, pose(0.0, 0.0, 179.0)));
        EXPECT_TRUE(f.keep(1.0, pose(0.3, 0.0, 179.0)));
        EXPECT_FALSE(f.keep(2.0, pose(0.3, 0.0, -90.0)));
        EXPECT_TRUE(f.keep(3.0, pose(0.3, 0.0, -90.0)));
    }
    {  // interval off: time alone is no reason
        MotionFilter f(params(0.2, 10.0, 0.0));
        ASSERT_TRUE(f.keep(0.0, pose(0.0, 0.0, 0.0)));
        EXPECT_FALSE(f.keep(1e9, pose(0.0, 0.0, 0.0)));
        EXPECT_TRUE(f.keep(1e9 + 1.0, pose(0.0, 0.0, 11.0)));
    }
    {  // everything off: only the first scan
        MotionFilter f(params(0.0, 0.0, 0.0));
        ASSERT_TRUE(f.keep(0.0, pose(0.0, 0.0, 0.0)));
        EXPECT_FALSE(f.keep(1e6, pose(1e3, 1e3, 180.0)));
        EXPECT_FALSE(f.keep(2e6, pose(-1e3, 5.0, -90.0)));
    }
}

TEST(MotionFilter, NoOdometryKeepsScan) {
    MotionFilter f;  // 0.2 m, 10 deg
    // Nothing to compare with: kept, and no reference is set.
    EXPECT_TRUE(f.keep(0.0, std::nullopt));
    EXPECT_TRUE(f.keep(0.1, std::nullopt));
    EXPECT_TRUE(f.keep(0.2, pose(5.0, 5.0, 0.0)));  // still the first scan with odometry
    EXPECT_FALSE(f.keep(0.3, pose(5.0, 5.0, 0.0)));
    // Kept without motion; the reference pose stays that of the last kept scan with odometry.
    EXPECT_TRUE(f.keep(0.4, std::nullopt));
    EXPECT_FALSE(f.keep(0.5, pose(5.1, 5.0, 5.0)));
    EXPECT_TRUE(f.keep(0.6, pose(5.25, 5.0, 5.0)));
    EXPECT_TRUE(f.keep(0.7, std::nullopt));
    EXPECT_FALSE(f.keep(0.8, pose(5.25, 5.1, 9.0)));
}

TEST(MotionFilter, AngleWrapsAroundPi) {
    MotionFilter f(params(0.0, 15.0, 0.0));
    ASSERT_TRUE(f.keep(kNaN, pose(0.0, 0.0, 175.0)));
    EXPECT_FALSE(f.keep(kNaN, pose(0.0, 0.0, -175.0)));  // 10 deg further on, not 350 back
    EXPECT_TRUE(f.keep(kNaN, pose(0.0, 0.0, -165.0)));   // 20 deg
    // Whole turns are no turn, whatever the representation of the heading.
    EXPECT_FALSE(f.keep(kNaN, pose(0.0, 0.0, -165.0 + 360.0)));
    EXPECT_FALSE(f.keep(kNaN, pose(0.0, 0.0, -165.0 + 720.0 + 5.0)));
    EXPECT_TRUE(f.keep(kNaN, pose(0.0, 0.0, -165.0 - 1080.0 + 16.0)));

    MotionFilter g(params(0.0, 15.0, 0.0));
    ASSERT_TRUE(g.keep(kNaN, pose(0.0, 0.0, -179.0)));
    EXPECT_FALSE(g.keep(kNaN, pose(0.0, 0.0, 179.0)));  // 2 deg
    EXPECT_TRUE(g.keep(kNaN, pose(0.0, 0.0, 0.0)));     // 179 deg
    EXPECT_TRUE(g.keep(kNaN, pose(0.0, 0.0, 180.0)));   // half a turn, the largest possible
}

TEST(MotionFilter, ResetForgetsReference) {
    MotionFilter f(params(0.2, 10.0, 0.0));
    ASSERT_TRUE(f.keep(0.0, pose(1.0, 1.0, 0.0)));
    ASSERT_FALSE(f.keep(1.0, pose(1.0, 1.0, 0.0)));
    f.reset();
    EXPECT_TRUE(f.keep(2.0, pose(1.0, 1.0, 0.0)));  // first scan again
    EXPECT_FALSE(f.keep(3.0, pose(1.0, 1.0, 0.0)));
    // The new reference is the first scan after the reset, not the old one.
    f.reset();
    EXPECT_TRUE(f.keep(4.0, pose(10.0, 0.0, 90.0)));
    EXPECT_FALSE(f.keep(5.0, pose(10.1, 0.0, 95.0)));
    EXPECT_TRUE(f.keep(6.0, pose(1.0, 1.0, 0.0)));

    // The time reference too (here every kept scan has a timestamp).
    MotionFilter g(params(0.0, 0.0, 5.0));
    const auto p = pose(0.0, 0.0, 0.0);
    ASSERT_TRUE(g.keep(100.0, p));
    g.reset();
    EXPECT_TRUE(g.keep(50.0, p));
    EXPECT_FALSE(g.keep(54.0, p));
    EXPECT_TRUE(g.keep(55.0, p));
}

TEST(MotionFilter, InvalidParamsThrow) {
    auto bad = [](MotionFilter::Params p) {
        EXPECT_THROW(MotionFilter{p}, kfd::ParameterError);
        MotionFilter f;
        EXPECT_THROW(f.initialize(p), kfd::ParameterError);
    };
    for (const double v : {-1.0, -1e-9, kNaN, kInf, -kInf}) {
        SCOPED_TRACE(v);
        bad(params(v, 10.0, 0.0));
        bad(params(0.2, v, 0.0));
        bad(params(0.2, 10.0, v));
    }
    EXPECT_NO_THROW(MotionFilter{params(0.0, 0.0, 0.0)});
    EXPECT_NO_THROW(MotionFilter{params(1e6, 360.0, 1e9)});
    MotionFilter f;
    f.initialize(params(0.5, 20.0, 3.0));
    EXPECT_EQ(f.params().max_distance_m, 0.5);
    EXPECT_EQ(f.params().max_angle_deg, 20.0);
    EXPECT_EQ(f.params().max_interval_s, 3.0);
}

// --- The baseline stages in the pipeline -----------------------------------------------------

TEST(PipelineBaselineStages, MotionStageDropsScans) {
    Pipeline::Params p;
    p.stages = {"motion"};
    p.get<kfd::MotionStage>() = params(0.5, 0.0, 0.0);
    Pipeline pipe(p, test::allStages());
    ASSERT_EQ(pipe.stages().size(), 1u);
    EXPECT_EQ(std::string(pipe.stages()[0]->name()), "motion");

    Scan scan = test::flatWall(91, test::deg2rad(90.0), 3.0);
    scan.timestamp = 0.0;
    scan.odometry = Pose2D{0.0, 0.0, 0.0};
    auto r = pipe.process(scan);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.dropped_by, "");

    scan.odometry = Pose2D{0.3, 0.0, 0.0};
    const Scan before = scan;
    r = pipe.process(scan);
    EXPECT_FALSE(r.keep);
    EXPECT_EQ(r.dropped_by, "motion");
    EXPECT_EQ(r.points_in, 91u);
    EXPECT_EQ(r.points_out, 91u);
    EXPECT_EQ(scan.valid, before.valid);  // dropping a scan does not touch its beams

    scan.odometry = Pose2D{0.5, 0.0, 0.0};
    r = pipe.process(scan);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.dropped_by, "");

    scan.odometry = std::nullopt;  // no odometry: kept
    EXPECT_TRUE(pipe.process(scan).keep);

    scan.odometry = Pose2D{0.5, 0.0, 0.0};
    EXPECT_EQ(pipe.process(scan).dropped_by, "motion");
    pipe.reset();  // forgets the reference: the same pose is a first scan again
    r = pipe.process(scan);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.dropped_by, "");
}

TEST(PipelineBaselineStages, MotionDropStopsTheChain) {
    Pipeline::Params p;
    p.stages = {"motion", "dbscan"};
    Pipeline pipe(p, test::allStages());

    Scan first = test::wallWithOutliers();
    first.odometry = Pose2D{0.0, 0.0, 0.0};
    auto r = pipe.process(first);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().points_in, 181u);
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().points_removed, 3u);

    Scan second = test::wallWithOutliers();
    second.odometry = Pose2D{0.01, 0.0, 0.0};
    r = pipe.process(second);
    EXPECT_FALSE(r.keep);
    EXPECT_EQ(r.dropped_by, "motion");
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().points_in,
              0u);  // the dbscan stage did not run
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().points_removed, 0u);
    EXPECT_EQ(second.countValid(), 181u);
    EXPECT_EQ(r.points_out, 181u);
}

TEST(PipelineBaselineStages, DbscanStageRemovesNoise) {
    Pipeline::Params p;
    p.stages = {"dbscan"};  // the paper's Eps 0.7 m, minPts 10
    Pipeline pipe(p, test::allStages());
    Scan scan = test::wallWithOutliers();
    const auto r = pipe.process(scan);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.dropped_by, "");
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().points_in, 181u);
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().clusters, 1u);
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().points_removed, 3u);
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.points_out, 178u);
    for (std::size_t i = 0; i < scan.size(); ++i) {
        const bool outlier = i == 20 || i == 90 || i == 150;
        EXPECT_EQ(scan.valid[i], outlier ? 0 : 1) << "beam " << i;
    }
}

TEST(PipelineBaselineStages, BadBaselineParamsThrowEvenWhenUnlisted) {
    Pipeline::Params p;  // default stages: neither motion nor dbscan
    p.get<kfd::MotionStage>().max_distance_m = -1.0;
    EXPECT_THROW(Pipeline(p, test::allStages()), kfd::ParameterError);
    p = Pipeline::Params{};
    p.get<kfd::DbscanStage>().eps_m = 0.0;
    EXPECT_THROW(Pipeline(p, test::allStages()), kfd::ParameterError);
    p = Pipeline::Params{};
    p.get<kfd::DbscanStage>().min_pts = 0;
    EXPECT_THROW(Pipeline(p, test::allStages()), kfd::ParameterError);
    p = Pipeline::Params{};
    p.stages = {"motion", "dbscan", "motion"};
    EXPECT_EQ(Pipeline(p, test::allStages()).stages().size(), p.stages.size());  // twice: allowed
}

}  // namespace
}  // namespace kfd
