#include "kfd/stages/denoise_stage.h"
#include "kfd/stages/evidence_denoise_stage.h"
#include "kfd/stages/range_aware_denoise_stage.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/algorithms/scan_tracker.h"
#include "kfd/paper/distance_filter.h"
#include "test_scans.h"

namespace kfd {
namespace {

using test::distinctLabels;
using test::emptyScan;
using test::setRange;
using test::setWall;

/// 181 beams over 180 deg (1 deg resolution), a flat wall 4 m ahead over beams 30-150
/// (-60..60 deg, 4 to 8 m), isolated outliers at 1.0 m on beams 50, 100 and 130, and a group
/// of four outliers at 0.8 m on beams 70-73 (close to the sensor: too narrow for any object).
Scan wallWithOutliers() {
    Scan scan = emptyScan(181, kPi);
    setWall(scan, 30, 150, 4.0);
    test::insertOutliers(scan, {50, 100, 130}, 1.0);
    setRange(scan, 70, 73, 0.8);
    return scan;
}

constexpr std::size_t kOutlierBeams[] = {50, 70, 71, 72, 73, 100, 130};

bool isOutlierBeam(std::size_t i) {
    for (const auto o : kOutlierBeams)
        if (o == i) return true;
    return false;
}

// One of the clustering stages with its default parameters, called as a denoiser: the
// stage's own diagnostics back (DenoiseResult) and its clusters.
class Denoiser {
  public:
    explicit Denoiser(DenoiseVariant v) {
        if (v == DenoiseVariant::Reference)
            stage_ = std::make_unique<DenoiseStage>();
        else if (v == DenoiseVariant::RangeAware)
            stage_ = std::make_unique<RangeAwareDenoiseStage>();
        else
            stage_ = std::make_unique<EvidenceDenoiseStage>();
    }
    template <class S>
    explicit Denoiser(const typename S::Params& p, S* /*type*/) : stage_(std::make_unique<S>(p)) {}
    DenoiseResult filter(Scan& scan) {
        StageReport report;
        const ScanReport chain{};
        EXPECT_TRUE(stage_->process(scan, report, chain));  // a denoiser never drops a scan
        EXPECT_TRUE(report.noise);
        const auto* r = report.diagnostics<DenoiseResult>();
        EXPECT_NE(r, nullptr);
        EXPECT_EQ(report.points_removed, r->points_removed);
        return *r;
    }
    const Clusters& clusters() const { return *stage_->clusters(); }

  private:
    std::unique_ptr<Stage> stage_;
};

DenoiseVariant variant(DenoiseVariant v) { return v; }

template <class S>
DenoiseResult run(const typename S::Params& p, Scan& scan) {
    return Denoiser(p, static_cast<S*>(nullptr)).filter(scan);
}

// The paper's denoise stage and kfd's range_aware_denoise on the same hand-made scans.
class DenoiserBothVariants : public ::testing::TestWithParam<DenoiseVariant> {};

TEST_P(DenoiserBothVariants, RemovesOutliersAndKeepsTheWallWhole) {
    Scan scan = wallWithOutliers();
    Denoiser d(variant(GetParam()));
    const auto res = d.filter(scan);
    for (std::size_t i = 0; i < scan.size(); ++i) {
        const bool wall = i >= 30 && i <= 150 && !isOutlierBeam(i);
        EXPECT_EQ(scan.valid[i] != 0, wall) << "beam " << i;
    }
    // The wall is one cluster, not a chain of pieces that happened to survive.
    EXPECT_EQ(distinctLabels(d.clusters().label, 30, 49), 1u);
    const auto wall = d.clusters().label[30];
    for (std::size_t i = 30; i <= 150; ++i)
        if (!isOutlierBeam(i)) {
            EXPECT_EQ(d.clusters().label[i], wall) << i;
        }
    EXPECT_EQ(res.points_in, 121u);
    EXPECT_EQ(res.points_removed, 7u);
    EXPECT_EQ(res.noise_clusters, 4u);  // three single outliers and the group
    EXPECT_EQ(res.clusters, 5u);
    EXPECT_EQ(res.variant, GetParam());
}

TEST_P(DenoiserBothVariants, NoiseFlagsMatchTheRemovedBeams) {
    Scan scan = wallWithOutliers();
    const Scan before = scan;
    Denoiser d(variant(GetParam()));
    d.filter(scan);
    const Clusters& c = d.clusters();
    for (std::size_t i = 0; i < scan.size(); ++i) {
        if (!before.valid[i]) {
            EXPECT_EQ(c.label[i], -1);
            continue;
        }
        ASSERT_GE(c.label[i], 0);
        EXPECT_EQ(c.noise[static_cast<std::size_t>(c.label[i])] != 0, scan.valid[i] == 0) << i;
    }
}

TEST_P(DenoiserBothVariants, KeepsRangesAndBeamCount) {
    Scan scan = wallWithOutliers();
    const Scan before = scan;
    Denoiser d(variant(GetParam()));
    d.filter(scan);
    EXPECT_EQ(scan.range, before.range);
    EXPECT_EQ(scan.size(), before.size());
    EXPECT_EQ(scan.geometry, before.geometry);
}

TEST_P(DenoiserBothVariants, AllInvalidScan) {
    Scan scan = emptyScan(181, kPi);
    Denoiser d(variant(GetParam()));
    const auto res = d.filter(scan);
    EXPECT_EQ(res.points_in, 0u);
    EXPECT_EQ(res.clusters, 0u);
    EXPECT_EQ(res.points_removed, 0u);
    EXPECT_EQ(scan.countValid(), 0u);
}

TEST_P(DenoiserBothVariants, OneBeamScan) {
    Scan scan = test::makeScan({2.0f});
    Denoiser d(variant(GetParam()));
    const auto res = d.filter(scan);
    EXPECT_EQ(res.points_in, 1u);
    EXPECT_EQ(res.clusters, 1u);
    // A lone point is below any bar of at least 2 points.
    EXPECT_EQ(res.points_removed, 1u);
    EXPECT_EQ(scan.countValid(), 0u);
    EXPECT_EQ(scan.range[0], 2.0f);
}

TEST_P(DenoiserBothVariants, EmptyScan) {
    Scan scan = test::makeScan({});
    Denoiser d(variant(GetParam()));
    const auto res = d.filter(scan);
    EXPECT_EQ(res.points_in, 0u);
    EXPECT_EQ(res.clusters, 0u);
}

TEST_P(DenoiserBothVariants, NaNRangesAfterDistanceFilter) {
    Scan scan = wallWithOutliers();
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (const std::size_t i : {31u, 60u, 61u, 90u, 149u}) scan.range[i] = nan;
    scan.range[120] = std::numeric_limits<float>::infinity();
    DistanceFilter().filter(scan);
    ASSERT_EQ(scan.countValid(), 121u - 6u);
    Denoiser d(variant(GetParam()));
    const auto res = d.filter(scan);
    EXPECT_EQ(res.points_in, 115u);
    EXPECT_EQ(res.points_removed, 7u);  // the same outliers; the wall bridges the holes
    for (const std::size_t i : {31u, 60u, 61u, 90u, 120u, 149u}) {
        EXPECT_EQ(scan.valid[i], 0u) << i;
        EXPECT_EQ(d.clusters().label[i], -1) << i;
    }
    EXPECT_EQ(distinctLabels(d.clusters().label, 30, 150), 5u);  // the wall + 4 noise clusters
}

TEST_P(DenoiserBothVariants, ReusedDenoiserForgetsThePreviousScan) {
    Denoiser d(variant(GetParam()));
    Scan first = wallWithOutliers();
    d.filter(first);
    Scan second = test::circle(360, 3.0);
    const auto res = d.filter(second);
    EXPECT_EQ(res.clusters, 1u);
    EXPECT_EQ(res.points_removed, 0u);
    EXPECT_EQ(d.clusters().label.size(), 360u);
}

INSTANTIATE_TEST_SUITE_P(Stage, DenoiserBothVariants,
                         ::testing::Values(DenoiseVariant::Reference, DenoiseVariant::RangeAware),
                         [](const ::testing::TestParamInfo<DenoiseVariant>& param_info) {
                             return std::string(param_info.param == DenoiseVariant::Reference
                                                    ? "Reference"
                                                    : "RangeAware");
                         });

/// The wall of wallWithOutliers() (no outliers) plus a small real object, 4 beams at 8 m on
/// beams 5-8, 22 deg away from the wall.
Scan wallAndFarSmallObject() {
    Scan scan = emptyScan(181, kPi);
    setWall(scan, 30, 150, 4.0);
    setRange(scan, 5, 8, 8.0);
    return scan;
}

TEST(DenoiseStage, RemovesAFarSmallObjectBelowTheFixedBar) {
    // The paper's fixed bar: 4 points < m_threshold = 10.
    Scan scan = wallAndFarSmallObject();
    Denoiser d(variant(DenoiseVariant::Reference));
    const auto res = d.filter(scan);
    EXPECT_EQ(res.points_removed, 4u);
    for (std::size_t i = 5; i <= 8; ++i) EXPECT_EQ(scan.valid[i], 0u) << i;
    EXPECT_EQ(scan.countValid(), 121u);
}

TEST(RangeAwareDenoiseStage, KeepsAFarSmallObjectWideEnough) {
    // 4 beams at 8 m span 0.56 m >= 0.1 m: the bar is the floor of 3 points.
    Scan scan = wallAndFarSmallObject();
    Denoiser d(variant(DenoiseVariant::RangeAware));
    const auto res = d.filter(scan);
    EXPECT_EQ(res.points_removed, 0u);
    EXPECT_EQ(res.clusters, 2u);
    EXPECT_EQ(scan.countValid(), 125u);
}

TEST(DenoiseStage, IgnoresMinObjectSizeItHasNone) {
    // The paper's fixed bar: the range-aware stage's min_object_size_m is not the paper's.
    Scan scan = wallAndFarSmallObject();
    EXPECT_EQ(run<DenoiseStage>(DenoiseStage::Params{}, scan).points_removed, 4u);
}

TEST(DenoiseStage, MThresholdIsConfigurable) {
    DenoiseStage::Params p;
    p.m_threshold = 4;  // the 4-point object now reaches the bar
    Scan scan = wallAndFarSmallObject();
    EXPECT_EQ(run<DenoiseStage>(p, scan).points_removed, 0u);
    p.m_threshold = 5;
    scan = wallAndFarSmallObject();
    EXPECT_EQ(run<DenoiseStage>(p, scan).points_removed, 4u);
}

TEST(RangeAwareDenoiseStage, MinPointsFloorIsConfigurable) {
    // The far object's range-adaptive bar is the floor: 4 points pass a floor of 4, not of 5.
    RangeAwareDenoiseStage::Params p;
    p.filter.min_points_floor = 4;
    Scan scan = wallAndFarSmallObject();
    EXPECT_EQ(run<RangeAwareDenoiseStage>(p, scan).points_removed, 0u);
    p.filter.min_points_floor = 5;
    scan = wallAndFarSmallObject();
    EXPECT_EQ(run<RangeAwareDenoiseStage>(p, scan).points_removed, 4u);
}

TEST(DenoiseStage, ResultReportsRingsAndBlocks) {
    Scan scan = wallAndFarSmallObject();
    DenoiseStage::Params p;
    p.clustering.rings.r_max = 20.0;  // r_1 = 8.94 m: everything in ring 1
    const auto res = run<DenoiseStage>(p, scan);
    EXPECT_EQ(res.variant, DenoiseVariant::Reference);
    EXPECT_DOUBLE_EQ(res.r_max, 20.0);
    EXPECT_EQ(res.blocks, 2u);
    EXPECT_EQ(res.merges, 0u);
    EXPECT_NEAR(res.theta_threshold, test::deg2rad(10.0), 1e-12);
}

TEST(DenoiseStage, AngleGapFactorWidensTheBlocks) {
    // With theta = 30 deg the far object (22 deg from the wall) joins the wall's block
    // (everything in ring 1 with r_max = 20 m) and is no longer removed.
    DenoiseStage::Params p;
    p.clustering.rings.r_max = 20.0;
    p.clustering.angle_gap_factor = 30.0;
    Scan scan = wallAndFarSmallObject();
    const auto res = run<DenoiseStage>(p, scan);
    EXPECT_EQ(res.clusters, 1u);
    EXPECT_NEAR(res.theta_threshold, test::deg2rad(30.0), 1e-12);
    RangeAwareDenoiseStage::Params q;
    q.clustering.angle_gap_factor = 30.0;
    scan = wallAndFarSmallObject();
    EXPECT_NEAR(run<RangeAwareDenoiseStage>(q, scan).theta_threshold, test::deg2rad(30.0), 1e-12);
}

TEST(DenoiseStage, DefaultsAreThePapers) {
    const DenoiseStage::Params p;
    EXPECT_EQ(p.clustering.rings.rings, 5u);
    EXPECT_EQ(p.m_threshold, 10u);
    EXPECT_DOUBLE_EQ(p.clustering.angle_gap_factor, 10.0);
    EXPECT_DOUBLE_EQ(RangeAwareDenoiseStage::Params{}.clustering.angle_gap_factor, 10.0);
    EXPECT_DOUBLE_EQ(RangeAwareDenoiseStage::Params{}.filter.min_object_size_m, 0.10);
}

TEST(DenoiseStage, EachStageReportsItsVariant) {
    for (const auto v :
         {DenoiseVariant::Reference, DenoiseVariant::RangeAware, DenoiseVariant::Evidence}) {
        Scan scan = wallWithOutliers();
        EXPECT_EQ(Denoiser(v).filter(scan).variant, v);
    }
    EXPECT_EQ(std::string(toString(DenoiseVariant::Reference)), "reference");
    EXPECT_EQ(std::string(toString(DenoiseVariant::RangeAware)), "range_aware");
    EXPECT_EQ(std::string(toString(DenoiseVariant::Evidence)), "evidence");
}

TEST(DenoiseStage, RejectsBadParams) {
    auto bad = [](auto mutate) {
        DenoiseStage::Params p;
        mutate(p);
        EXPECT_THROW(DenoiseStage{p}, kfd::ParameterError);
    };
    bad([](auto& p) { p.m_threshold = 0; });
    bad([](auto& p) { p.clustering.rings.rings = 0; });
    bad([](auto& p) { p.clustering.rings.r_max = -1.0; });
    bad([](auto& p) { p.clustering.angle_gap_factor = 0.0; });
    bad([](auto& p) { p.clustering.merge_distance_m = -1.0; });
}

TEST(RangeAwareDenoiseStage, RejectsBadParams) {
    auto bad = [](auto mutate) {
        RangeAwareDenoiseStage::Params p;
        mutate(p);
        EXPECT_THROW(RangeAwareDenoiseStage{p}, kfd::ParameterError);
    };
    bad([](auto& p) { p.filter.m_threshold = 0; });
    bad([](auto& p) { p.filter.min_points_floor = 0; });
    bad([](auto& p) { p.filter.min_object_size_m = -0.1; });
    bad([](auto& p) { p.filter.min_object_size_m = std::nan(""); });
    bad([](auto& p) { p.clustering.angle_gap_factor = 0.0; });
    bad([](auto& p) { p.clustering.jump_lambda_deg = 90.0; });
    bad([](auto& p) { p.clustering.jump_sigma_m = -0.01; });
}

}  // namespace

// Issue 39, item 2: the stage reads where the track stage placed the scan from the chain.
ScanReport trackedChain(double x) {
    TrackResult t;
    t.verdict = TrackVerdict::Tracked;
    t.pose = Pose2D{x, 0.0, 0.0};
    t.rms_m = 0.01f;
    ScanReport chain;
    chain.stage_reports[0].setDiagnostics(t);
    chain.stage_count = 1;
    return chain;
}

TEST(EvidenceDenoiseStage, TakesTheTrackersPosesFromTheChain) {
    // The odometry jumps 5 m (beyond max_step_m: no temporal evidence from it); the track
    // stage placed both scans 0.1 m apart, and the stage uses that (track_alignment).
    EvidenceDenoiseStage::Params p;
    p.track_alignment = true;
    for (const bool tracked : {true, false}) {
        EvidenceDenoiseStage stage(p);
        StageReport report;
        Scan first = test::flatWall(361, test::deg2rad(150.0), 4.0);
        first.odometry = Pose2D{};
        Scan second = test::flatWall(361, test::deg2rad(150.0), 3.9);
        second.odometry = Pose2D{5.0, 0.0, 0.0};
        stage.process(first, report, tracked ? trackedChain(0.0) : ScanReport{});
        stage.process(second, report, tracked ? trackedChain(0.1) : ScanReport{});
        EXPECT_EQ(report.diagnostics<DenoiseResult>()->temporal, tracked);
    }
}

}  // namespace kfd
