// The core on pathological scans (fed directly, as the fuzz targets do): a bad geometry is a
// kfd::ScanError before any stage runs, and no range value (NaN, +-inf, negative, huge) flagged
// valid makes any stage misbehave.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "kfd/paper/clusters.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/pipeline/stage_registry.h"
#include "kfd/stages/core_stages.h"
#include "kfd/stages/denoise_stage.h"
#include "test_scans.h"

namespace {

using kfd::Pipeline;
using kfd::Scan;
using kfd::ScanSkipReason;
constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr float kInff = std::numeric_limits<float>::infinity();

// Every single core stage alone, each core stage pair, and the default chain: the stage lists
// a fuzzer may build.
std::vector<std::vector<std::string>> stageLists() {
    std::vector<std::vector<std::string>> lists{{}};
    const auto& stages = kfd::coreStageRegistry().stages();
    for (const auto& a : stages) {
        lists.push_back({a.name});
        for (const auto& b : stages)
            if (a.name != b.name) lists.push_back({a.name, b.name});
    }
    lists.push_back({"distance", "keyframe", "denoise"});
    lists.push_back({"distance", "view_keyframe", "evidence_denoise"});
    return lists;
}

// A scan with every kind of bad range flagged valid, around a clean wall.
Scan poisonedWall(std::size_t beams, double aperture) {
    Scan s = kfd::test::flatWall(beams, aperture, 2.0);
    const float bad[] = {kNaNf, kInff, -kInff, -1.0f, 1e30f, 3e38f, 0.0f};
    for (std::size_t i = 0; i < beams; i += 3) s.range[i] = bad[(i / 3) % 7];
    return s;
}

}  // namespace

TEST(CoreBadScan, GeometryOutsideTheLimitsIsAScanErrorAndTheScanIsUntouched) {
    struct Case {
        std::size_t beams;
        double aperture;
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const Case c : {Case{100, 0.0}, Case{100, -1.0}, Case{100, nan}, Case{100, 1e300},
                         Case{100, 7.0}, Case{100, kfd::test::kInf}, Case{1, kfd::kPi},
                         Case{0, kfd::kPi}, Case{kfd::kMaxScanBeams + 1, kfd::kPi}}) {
        SCOPED_TRACE(std::to_string(c.beams) + " beams, aperture " + std::to_string(c.aperture));
        for (const auto& list : stageLists()) {
            Pipeline::Params p;
            p.stages = list;
            Pipeline pipe(p);
            Scan s = kfd::test::flatWall(
                c.beams, c.aperture > 0 && c.aperture < 7 ? c.aperture : kfd::kPi, 2.0);
            s.geometry.aperture = c.aperture;
            const auto before = s.valid;
            EXPECT_THROW(pipe.process(s), kfd::ScanError);
            EXPECT_EQ(s.valid, before);
        }
    }
}

TEST(CoreBadScan, GeometryLimitsAreTheDocumentedOnes) {
    kfd::ScanGeometry g;
    g.aperture = kfd::kPi;
    g.beams = 2;
    EXPECT_EQ(kfd::checkGeometry(g), ScanSkipReason::None);
    g.beams = 65536;
    EXPECT_EQ(kfd::checkGeometry(g), ScanSkipReason::None);
    g.beams = 65537;
    EXPECT_EQ(kfd::checkGeometry(g), ScanSkipReason::TooManyBeams);
    g.beams = 1;
    EXPECT_EQ(kfd::checkGeometry(g), ScanSkipReason::NoBeams);
    g.beams = 360;
    g.aperture = static_cast<float>(2.0 * kfd::kPi);  // MRPT stores the aperture as float
    EXPECT_EQ(kfd::checkGeometry(g), ScanSkipReason::None);
    g.aperture = 2.0 * kfd::kPi * 1.001;
    EXPECT_EQ(kfd::checkGeometry(g), ScanSkipReason::BadAperture);
    EXPECT_STREQ(kfd::toString(ScanSkipReason::BadAperture), "bad_aperture");
}

TEST(CoreBadScan, BadRangesFlaggedValidNeverMisleadAnyStage) {
    for (const double aperture : {kfd::kPi, kfd::test::fullCircleAperture(720), 1e-6}) {
        for (const auto& list : stageLists()) {
            SCOPED_TRACE(std::to_string(aperture) + " rad, " + std::to_string(list.size()) +
                         " stages" + (list.empty() ? "" : " from " + list[0]));
            Pipeline::Params p;
            p.stages = list;
            p.get<kfd::RangeAwareDenoiseStage>().filter.min_object_size_m = 0.3;
            Pipeline pipe(p);
            for (int k = 0; k < 3; ++k) {  // first scan and later ones (keyframe references)
                Scan s = poisonedWall(720, aperture);
                const auto r = pipe.process(s);
                EXPECT_LE(r.points_out, r.points_in);
                EXPECT_EQ(r.points_out, s.countValid());
            }
        }
    }
}

TEST(CoreBadScan, TheDenoiserRemovesBeamsWithoutAUsableRange) {
    for (const auto variant : {kfd::DenoiseVariant::Reference, kfd::DenoiseVariant::RangeAware,
                               kfd::DenoiseVariant::Evidence}) {
        Pipeline::Params p;
        p.stages = {kfd::stageName(variant)};
        Pipeline pipe(p);
        Scan s = poisonedWall(720, kfd::kPi);
        pipe.process(s);
        for (std::size_t i = 0; i < s.size(); ++i) {
            if (!std::isfinite(s.range[i]) || s.range[i] < 0.0f) {
                EXPECT_EQ(s.valid[i], 0u) << i << " range " << s.range[i];
            }
        }
    }
}

TEST(CoreBadScan, ClusterSizeBarIsTheFixedThresholdForANaNOrInfiniteMeanRange) {
    kfd::ClusterFilterParams p;
    p.m_threshold = 10;
    p.min_object_size_m = 0.3;
    p.min_points_floor = 3;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(kfd::minClusterPoints(p, nan, 0.01), 10u);
    EXPECT_EQ(kfd::minClusterPoints(p, 1.0, nan), 10u);
    EXPECT_EQ(kfd::minClusterPoints(p, kfd::test::kInf, 0.01), 3u);  // far: the floor
    EXPECT_EQ(kfd::minClusterPoints(p, 1e-300, 1e-300), 10u);        // huge bar: clamped
    EXPECT_EQ(kfd::minClusterPoints(p, -1.0, 0.01), 10u);
}
