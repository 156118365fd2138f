// The baseline stages' registration: after the core, each with its own keys and diagnostics.
#include "kfd/baselines/stages.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "baselines/all_stages.h"
#include "test_scans.h"

namespace kfd {
namespace {

TEST(BaselineStages, RegisteredAfterTheCoreStages) {
    EXPECT_EQ(test::allStages().names(),
              "distance, keyframe, denoise, view_keyframe, range_aware_denoise, "
              "evidence_denoise, odometry_check, fuse, track, motion, dbscan, radius, sor, shadow, "
              "speckle, decimate");
    StageRegistry only;
    registerBaselineStages(only);  // works without the core stages too
    EXPECT_EQ(only.names(), "motion, dbscan, radius, sor, shadow, speckle, decimate");
    EXPECT_THROW(registerBaselineStages(only), Error);  // twice: names are taken
}

TEST(BaselineStages, KeysKeepTheirFlatNames) {
    std::vector<std::string> names;
    for (const char* s : {"motion", "dbscan", "radius", "sor", "shadow", "speckle"})
        for (const auto& k : test::allStages().find(s)->keys) names.push_back(k.name);
    EXPECT_EQ(names,
              (std::vector<std::string>{
                  "motion_distance_m", "motion_angle_deg", "motion_interval_s", "dbscan_eps_m",
                  "dbscan_min_pts", "radius_m", "radius_min_neighbors", "sor_k", "sor_std_mul",
                  "shadow_min_angle_deg", "shadow_max_angle_deg", "shadow_window",
                  "shadow_neighbors", "shadow_remove_start", "speckle_radius", "speckle_max_range",
                  "speckle_max_range_difference", "speckle_window"}));
    // A key names its Params field for the core's errors.
    const StageInfo& sor = *test::allStages().find("sor");
    EXPECT_EQ(sor.keyForField("k")->name, "sor_k");
    PipelineParams p;
    try {
        sor.keyForField("k")->set(p.at(sor).data(), "0");
        FAIL() << "sor_k = 0 accepted";
    } catch (const ParameterError& e) {
        EXPECT_EQ(e.field(), "k");
    }
}

TEST(BaselineStages, DenoisingBaselinesCountAsNoise) {
    for (const char* s : {"dbscan", "radius", "sor", "shadow", "speckle"}) {
        SCOPED_TRACE(s);
        PipelineParams p;
        p.stages = {"distance", s};
        Pipeline pipe(p, test::allStages());
        Scan scan = test::emptyScan(181, kPi);
        test::setWall(scan, 30, 150, 4.0);
        test::insertOutliers(scan, {60, 90, 120}, 1.0);
        const ScanReport r = pipe.process(scan);
        ASSERT_NE(r.stage(s), nullptr);
        EXPECT_TRUE(r.stage(s)->noise);
        EXPECT_GE(r.stage(s)->points_removed, 3u);
        EXPECT_EQ(r.noiseRemoved(), r.stage(s)->points_removed);
    }
    PipelineParams p;
    p.stages = {"motion"};
    Pipeline pipe(p, test::allStages());
    Scan scan = test::emptyScan(181, kPi);
    scan.odometry = Pose2D{0.0, 0.0, 0.0};
    EXPECT_TRUE(pipe.process(scan).keep);  // the first scan is kept
    Scan same = scan;
    const ScanReport r = pipe.process(same);  // no motion: dropped by the motion stage
    EXPECT_FALSE(r.keep);
    EXPECT_EQ(r.dropped_by, "motion");
    EXPECT_TRUE(r.stage("motion")->dropped);
}

}  // namespace
}  // namespace kfd
