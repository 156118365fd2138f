#include "kfd/baselines/radius_outlier.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "baselines/all_stages.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/stages/core_stages.h"
#include "test_scans.h"

namespace kfd {
namespace {

using test::kInf;
using test::kNaN;

RadiusOutlierFilter::Params params(double radius_m, std::size_t min_neighbors) {
    RadiusOutlierFilter::Params p;
    p.radius_m = radius_m;
    p.min_neighbors = min_neighbors;
    return p;
}

// test::line: points on one line, so that the tests can put points exactly at the radius.
using test::line;

std::string whatOf(const RadiusOutlierFilter::Params& p) {
    return test::constructionError<RadiusOutlierFilter>(p);
}

// --- Parameters -----------------------------------------------------------------------------

TEST(RadiusOutlierFilter, Defaults) {
    const RadiusOutlierFilter::Params p;
    EXPECT_EQ(p.radius_m, 0.3);      // kfd's default for indoor 2D scans
    EXPECT_EQ(p.min_neighbors, 3u);  // kfd's default
    const RadiusOutlierFilter f;
    EXPECT_EQ(f.params().radius_m, 0.3);
    EXPECT_EQ(f.params().min_neighbors, 3u);
    const RadiusOutlierFilter g(params(0.75, 5));
    EXPECT_EQ(g.params().radius_m, 0.75);
    EXPECT_EQ(g.params().min_neighbors, 5u);
}

TEST(RadiusOutlierFilter, InvalidParamsThrowNamingTheKey) {
    for (const double r : {0.0, -0.0, -0.3, kNaN, kInf, -kInf}) {
        SCOPED_TRACE(r);
        EXPECT_THROW(RadiusOutlierFilter{params(r, 3)}, kfd::ParameterError);
        RadiusOutlierFilter f;
        EXPECT_THROW(f.initialize(params(r, 3)), kfd::ParameterError);
        EXPECT_EQ(f.params().radius_m, 0.3);  // a failed initialize keeps the old parameters
        EXPECT_NE(whatOf(params(r, 3)).find("radius_m"), std::string::npos) << whatOf(params(r, 3));
    }
    EXPECT_THROW(RadiusOutlierFilter{params(0.3, 0)}, kfd::ParameterError);
    EXPECT_NE(whatOf(params(0.3, 0)).find("radius_min_neighbors"), std::string::npos);
    EXPECT_EQ(whatOf(params(1e-6, 1)), "<no error>");
    EXPECT_EQ(whatOf(params(100.0, 1000000)), "<no error>");
}

// --- Hand-made scans ------------------------------------------------------------------------

TEST(RadiusOutlierFilter, DenseWallStays) {
    RadiusOutlierFilter f;                                      // 0.3 m, 3 neighbours
    Scan scan = test::flatWall(181, test::deg2rad(90.0), 3.0);  // points 2.6-5.2 cm apart
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.points_removed, 0u);
    EXPECT_EQ(scan.countValid(), 181u);
}

TEST(RadiusOutlierFilter, IsolatedOutliersAreRemoved) {
    RadiusOutlierFilter f;
    Scan scan = test::wallWithOutliers();       // outliers at beams 20, 150 (behind), 90 (in front)
    test::insertOutliers(scan, {60, 61}, 9.0);  // a pair: one neighbour each
    test::setRange(scan, 110, 113, 9.0);        // four 7.9 cm apart: 3 others each, kept
    const Scan input = scan;
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.points_removed, 5u);
    EXPECT_EQ(scan.range, input.range);  // only valid flags change
    for (std::size_t i = 0; i < 181; ++i) {
        const bool outlier = i == 20 || i == 150 || i == 90 || i == 60 || i == 61;
        EXPECT_EQ(scan.valid[i], outlier ? 0 : 1) << "beam " << i;
    }
}

TEST(RadiusOutlierFilter, ExactlyAtTheRadiusAndExactlyMinNeighbors) {
    // Points at x = 10, 11, 12, 13 and 20 (exact distances).
    const Scan input = line({10.0f, 11.0f, 12.0f, 13.0f, 20.0f});
    auto run = [&](double radius, std::size_t min_neighbors) {
        Scan s = input;
        RadiusOutlierFilter f(params(radius, min_neighbors));
        const auto r = f.filter(s);
        EXPECT_EQ(r.points_in, 5u);
        EXPECT_EQ(r.points_removed, s.size() - s.countValid());
        return s.valid;
    };
    // Neighbours exactly 1 m away are within a 1 m radius.
    EXPECT_EQ(run(1.0, 1), test::flags({1, 1, 1, 1, 0}));
    EXPECT_EQ(run(0.999, 1), test::flags({0, 0, 0, 0, 0}));
    // 11 and 12 have exactly 2 others within 1 m: enough for 2, not for 3.
    EXPECT_EQ(run(1.0, 2), test::flags({0, 1, 1, 0, 0}));
    EXPECT_EQ(run(1.0, 3), test::flags({0, 0, 0, 0, 0}));
    // Within 2 m: 10 and 13 have 2 others, 11 and 12 have 3.
    EXPECT_EQ(run(2.0, 2), test::flags({1, 1, 1, 1, 0}));
    EXPECT_EQ(run(2.0, 3), test::flags({0, 1, 1, 0, 0}));
    // 20 is 7 m from 13.
    EXPECT_EQ(run(7.0, 1), test::flags({1, 1, 1, 1, 1}));
    EXPECT_EQ(run(6.5, 1), test::flags({1, 1, 1, 1, 0}));
}

TEST(RadiusOutlierFilter, ThePointItselfIsNotCountedButDuplicatesAre) {
    RadiusOutlierFilter f(params(0.5, 1));
    Scan lone = line({4.0f});
    EXPECT_EQ(f.filter(lone).points_removed, 1u);  // counting itself it would have 1
    Scan pair = line({4.0f, 4.0f, 9.0f});          // two points at the same place
    const auto r = f.filter(pair);
    EXPECT_EQ(r.points_removed, 1u);
    EXPECT_EQ(pair.valid, test::flags({1, 1, 0}));
}

TEST(RadiusOutlierFilter, EveryPointIsJudgedOnTheInputScan) {
    // x = 5, 5.5, 6 with 0.5 m and 2 neighbours: the ends go, and the middle keeps its two
    // (now removed) neighbours. Removing points one by one would cascade to an empty scan.
    RadiusOutlierFilter f(params(0.5, 2));
    Scan s = line({5.0f, 5.5f, 6.0f});
    EXPECT_EQ(f.filter(s).points_removed, 2u);
    EXPECT_EQ(s.valid, test::flags({0, 1, 0}));
}

TEST(RadiusOutlierFilter, InvalidBeamsAreIgnored) {
    RadiusOutlierFilter f(params(0.5, 1));
    Scan s = line({4.0f, 4.2f, 7.0f, 7.1f});
    s.valid = test::flags({1, 0, 0, 1});  // each valid point's only neighbour is invalid
    const auto r = f.filter(s);
    EXPECT_EQ(r.points_in, 2u);
    EXPECT_EQ(r.points_removed, 2u);
    EXPECT_EQ(s.valid, test::flags({0, 0, 0, 0}));
}

TEST(RadiusOutlierFilter, NonFiniteRangesAreRemoved) {
    RadiusOutlierFilter f(params(0.5, 1));
    Scan s = line({4.0f, 4.2f, std::numeric_limits<float>::quiet_NaN(),
                   std::numeric_limits<float>::infinity(), 4.1f});
    s.valid = test::flags({1, 1, 1, 1, 0});
    const auto r = f.filter(s);
    EXPECT_EQ(r.points_in, 4u);
    EXPECT_EQ(r.points_removed, 2u);
    EXPECT_EQ(s.valid, test::flags({1, 1, 0, 0, 0}));
}

TEST(RadiusOutlierFilter, EmptyScans) {
    RadiusOutlierFilter f;
    Scan none = test::emptyScan(50, kPi);
    auto r = f.filter(none);
    EXPECT_EQ(r.points_in, 0u);
    EXPECT_EQ(r.points_removed, 0u);
    Scan zero = test::makeScan({});
    r = f.filter(zero);
    EXPECT_EQ(r.points_in, 0u);
    EXPECT_EQ(r.points_removed, 0u);
}

TEST(RadiusOutlierFilter, BuffersFromALargerScanDoNotLeak) {
    RadiusOutlierFilter f(params(0.4, 3));
    auto [big, small] = test::largeThenSmallScans();
    Scan smallCopy = small;
    f.filter(big);
    const auto r = f.filter(small);
    RadiusOutlierFilter fresh(params(0.4, 3));
    const auto rf = fresh.filter(smallCopy);
    EXPECT_EQ(small.valid, smallCopy.valid);
    EXPECT_EQ(r.points_in, rf.points_in);
    EXPECT_EQ(r.points_removed, rf.points_removed);
}

// --- As a pipeline stage --------------------------------------------------------------------

TEST(RadiusOutlierFilter, PipelineStage) {
    Pipeline::Params p;
    p.stages = {"distance", "radius"};
    p.get<kfd::DistanceStage>().max_range = 5.0;  // beam 20 and 150 (8 m) go in the distance stage
    Pipeline pipe(p, test::allStages());
    ASSERT_EQ(pipe.stages().size(), 2u);
    EXPECT_STREQ(pipe.stages()[1]->name(), "radius");
    Scan scan = test::wallWithOutliers();
    auto r = pipe.process(scan);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.dropped_by, "");
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.findOrDefault<kfd::RadiusOutlierFilter::Result>().points_in, 179u);
    EXPECT_EQ(r.findOrDefault<kfd::RadiusOutlierFilter::Result>().points_removed, 1u);  // the spike
    EXPECT_EQ(r.noiseRemoved(), 1u);
    EXPECT_EQ(r.points_out, 178u);
    EXPECT_EQ(scan.valid[90], 0);
    EXPECT_EQ(r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().points_in,
              0u);  // other baselines did not run
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().points_in, 0u);

    // Parameters reach the stage: a 0.01 m radius leaves the wall points (>= 2.6 cm apart)
    // without neighbours.
    p.get<kfd::RadiusStage>() = params(0.01, 1);
    pipe.initialize(p);
    scan = test::wallWithOutliers();
    r = pipe.process(scan);
    EXPECT_EQ(r.findOrDefault<kfd::RadiusOutlierFilter::Result>().points_removed, 179u);
    EXPECT_EQ(r.points_out, 0u);

    // Without the stage nothing is reported.
    p.stages = {"distance"};
    pipe.initialize(p);
    scan = test::wallWithOutliers();
    r = pipe.process(scan);
    EXPECT_EQ(r.findOrDefault<kfd::RadiusOutlierFilter::Result>().points_in, 0u);
    EXPECT_EQ(r.points_out, 179u);
}

TEST(RadiusOutlierFilter, PipelineValidatesTheStageEvenWhenUnlisted) {
    Pipeline::Params p;  // default stages: no radius
    p.get<kfd::RadiusStage>().radius_m = -1.0;
    EXPECT_THROW(Pipeline(p, test::allStages()), kfd::ParameterError);
    p = Pipeline::Params{};
    p.get<kfd::RadiusStage>().min_neighbors = 0;
    EXPECT_THROW(Pipeline(p, test::allStages()), kfd::ParameterError);
    p = Pipeline::Params{};
    p.stages = {"radius", "distance", "radius"};
    EXPECT_EQ(Pipeline(p, test::allStages()).stages().size(), p.stages.size());  // twice: allowed
    p.stages = {"radial"};
    try {
        Pipeline(p, test::allStages());
        FAIL() << "unknown stage accepted";
    } catch (const kfd::ParameterError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("radial"), std::string::npos) << what;
        EXPECT_NE(what.find("radius"), std::string::npos) << what;
        EXPECT_NE(what.find("sor"), std::string::npos) << what;
    }
}

// --- Against a plain O(n^2) radius outlier removal ------------------------------------------

/// Exhaustive search with the filter's arithmetic: coordinates from double trigonometry, then
/// float; squared distances in float against radius^2 (float). Returns the expected output
/// valid flags.
std::vector<std::uint8_t> plainRadiusOutlier(const Scan& s, double radius_m,
                                             std::size_t min_neighbors) {
    const test::Points p = test::cartesian(s);
    std::vector<std::uint8_t> out = test::withPosition(s);
    const float r = static_cast<float>(radius_m);
    const float r2 = r * r;
    for (std::size_t i = 0; i < p.size(); ++i) {
        std::size_t others = 0;
        for (const float d2 : test::squaredDistancesFrom(p, i)) others += d2 <= r2;
        if (others < min_neighbors) out[p.beam[i]] = 0;
    }
    return out;
}

TEST(RadiusOutlierFilter, ReferenceAgreesWithHandMadeCase) {
    // Guards the reference the random comparison relies on.
    const Scan s = line({10.0f, 11.0f, 12.0f, 13.0f, 20.0f});
    EXPECT_EQ(plainRadiusOutlier(s, 1.0, 2), test::flags({0, 1, 1, 0, 0}));
    EXPECT_EQ(plainRadiusOutlier(s, 2.0, 2), test::flags({1, 1, 1, 1, 0}));
}

TEST(RadiusOutlierFilter, MatchesPlainImplementationOnRandomScans) {
    RadiusOutlierFilter f;  // one filter for every scan: buffers are reused across sizes
    std::size_t removed = 0, kept = 0, partial = 0;
    const int kScans = 300;
    for (int seed = 1; seed <= kScans; ++seed) {
        std::mt19937 rng(static_cast<unsigned>(seed));
        const std::size_t beams = std::uniform_int_distribution<std::size_t>(20, 720)(rng);
        const double aperture = test::randomAperture(rng, beams);
        RadiusOutlierFilter::Params p;  // every fourth scan with the defaults
        if (seed % 4 != 0) {
            p.radius_m = std::uniform_real_distribution<double>(0.02, 1.2)(rng);
            p.min_neighbors = std::uniform_int_distribution<std::size_t>(1, 15)(rng);
        }
        f.initialize(p);
        Scan input = test::randomScan(rng, beams, aperture);
        if (seed % 5 == 0) test::addBeamsWithoutPosition(input);  // valid, without a position
        Scan output = input;
        const auto res = f.filter(output);
        const auto expected = plainRadiusOutlier(input, p.radius_m, p.min_neighbors);
        SCOPED_TRACE("seed " + std::to_string(seed) + ", " + std::to_string(beams) +
                     " beams, radius " + std::to_string(p.radius_m) + ", min_neighbors " +
                     std::to_string(p.min_neighbors));
        ASSERT_EQ(output.valid, expected);
        for (std::size_t i = 0; i < beams; ++i)  // ranges untouched (NaN compares unequal)
            ASSERT_EQ(std::memcmp(&output.range[i], &input.range[i], sizeof(float)), 0) << i;
        ASSERT_EQ(res.points_in, input.countValid());
        ASSERT_EQ(res.points_removed, input.countValid() - output.countValid());
        removed += res.points_removed;
        kept += output.countValid();
        partial += res.points_removed > 0 && output.countValid() > 0;
    }
    // Not vacuous: many points go, many stay, and most scans lose some but not all.
    EXPECT_GT(removed, 5000u);
    EXPECT_GT(kept, 20000u);
    EXPECT_GT(partial, static_cast<std::size_t>(kScans / 2));
}

}  // namespace
}  // namespace kfd
