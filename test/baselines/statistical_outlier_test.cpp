#include "kfd/baselines/statistical_outlier.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
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

StatisticalOutlierFilter::Params params(std::size_t k, double std_mul) {
    StatisticalOutlierFilter::Params p;
    p.k = k;
    p.std_mul = std_mul;
    return p;
}

// test::line: points on one line, so that distances, their means and the statistics below are
// exact in binary.
using test::line;

std::string whatOf(const StatisticalOutlierFilter::Params& p) {
    return test::constructionError<StatisticalOutlierFilter>(p);
}

// --- Parameters -----------------------------------------------------------------------------

TEST(StatisticalOutlierFilter, Defaults) {
    const StatisticalOutlierFilter::Params p;
    EXPECT_EQ(p.k, 8u);  // kfd's defaults
    EXPECT_EQ(p.std_mul, 1.0);
    const StatisticalOutlierFilter f;
    EXPECT_EQ(f.params().k, 8u);
    EXPECT_EQ(f.params().std_mul, 1.0);
    const StatisticalOutlierFilter g(params(20, 2.5));
    EXPECT_EQ(g.params().k, 20u);
    EXPECT_EQ(g.params().std_mul, 2.5);
}

TEST(StatisticalOutlierFilter, InvalidParamsThrowNamingTheKey) {
    EXPECT_THROW(StatisticalOutlierFilter{params(0, 1.0)}, kfd::ParameterError);
    // k is bounded (the per-scan work is O(n (log n + k))).
    EXPECT_NO_THROW(StatisticalOutlierFilter{params(kfd::kMaxSorNeighbours, 1.0)});
    EXPECT_THROW(StatisticalOutlierFilter{params(kfd::kMaxSorNeighbours + 1, 1.0)},
                 kfd::ParameterError);
    EXPECT_NE(whatOf(params(0, 1.0)).find("sor_k"), std::string::npos);
    for (const double m : {-0.5, -1e-9, kNaN, kInf, -kInf}) {
        SCOPED_TRACE(m);
        EXPECT_THROW(StatisticalOutlierFilter{params(8, m)}, kfd::ParameterError);
        StatisticalOutlierFilter f;
        EXPECT_THROW(f.initialize(params(8, m)), kfd::ParameterError);
        EXPECT_EQ(f.params().std_mul, 1.0);  // a failed initialize keeps the old parameters
        EXPECT_NE(whatOf(params(8, m)).find("sor_std_mul"), std::string::npos);
    }
    EXPECT_EQ(whatOf(params(1, 0.0)), "<no error>");
    EXPECT_EQ(whatOf(params(1000, 100.0)), "<no error>");
}

// --- Hand-made scans ------------------------------------------------------------------------

TEST(StatisticalOutlierFilter, WallKeptIsolatedOutliersRemoved) {
    StatisticalOutlierFilter f;                 // k 8, 1 sigma
    Scan scan = test::wallWithOutliers();       // outliers at beams 20, 150 (behind), 90 (in front)
    test::insertOutliers(scan, {60, 61}, 9.0);  // a pair: one near neighbour of 8
    const Scan input = scan;
    const auto r = f.filter(scan);
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.points_removed, 5u);
    EXPECT_EQ(scan.range, input.range);  // only valid flags change
    for (std::size_t i = 0; i < 181; ++i) {
        const bool outlier = i == 20 || i == 150 || i == 90 || i == 60 || i == 61;
        EXPECT_EQ(scan.valid[i], outlier ? 0 : 1) << "beam " << i;
    }
    EXPECT_GT(r.stddev_distance, 0.0);
    EXPECT_EQ(r.threshold, r.mean_distance + 1.0 * r.stddev_distance);
    for (std::size_t i = 0; i < 181; ++i)
        EXPECT_EQ(f.meanDistances()[i] > r.threshold, scan.valid[i] == 0) << i;
}

TEST(StatisticalOutlierFilter, ExactThreshold) {
    // k = 1: d_i is the distance to the nearest other point. Pair at 1, 2 (d = 1, 1), pair at
    // 100, 105 (d = 5, 5), 13 points 3 apart from 200 (d = 3 each): mu = 51 / 17 = 3 and
    // sigma = sqrt(16 / 16) = 1, all exact.
    std::vector<float> ranges{1.0f, 2.0f, 100.0f, 105.0f};
    for (int i = 0; i < 13; ++i) ranges.push_back(200.0f + 3.0f * static_cast<float>(i));
    const Scan input = line(ranges);
    auto run = [&](double std_mul) {
        Scan s = input;
        StatisticalOutlierFilter f(params(1, std_mul));
        const auto r = f.filter(s);
        EXPECT_EQ(r.points_in, 17u);
        EXPECT_EQ(r.mean_distance, 3.0);
        EXPECT_EQ(r.stddev_distance, 1.0);
        EXPECT_EQ(r.threshold, 3.0 + std_mul);
        EXPECT_EQ(f.meanDistances()[0], 1.0);
        EXPECT_EQ(f.meanDistances()[3], 5.0);
        EXPECT_EQ(f.meanDistances()[16], 3.0);
        EXPECT_EQ(r.points_removed, s.size() - s.countValid());
        return s.countValid() == 17
                   ? std::string("all")
                   : std::to_string(s.valid[2]) + std::to_string(s.valid[3]) +
                         std::to_string(s.valid[4]) + "/" + std::to_string(s.countValid());
    };
    EXPECT_EQ(run(2.0), "all");       // the pair at exactly mu + 2 sigma = 5 stays
    EXPECT_EQ(run(1.999), "001/15");  // just below: the pair at 5 goes
    EXPECT_EQ(run(0.0), "001/15");    // threshold = mu: the 13 at exactly 3 stay
    EXPECT_EQ(run(100.0), "all");
}

TEST(StatisticalOutlierFilter, FewerPointsThanKUsesAllOthers) {
    // Points at 10, 11, 13 with k = 8: d = (1 + 3) / 2, (1 + 2) / 2, (3 + 2) / 2 = 2, 1.5, 2.5;
    // mu = 2, sigma = sqrt(0.5 / 2) = 0.5; 13 sits exactly at mu + 1 sigma.
    const Scan input = line({10.0f, 11.0f, 13.0f});
    Scan s = input;
    StatisticalOutlierFilter f(params(8, 1.0));
    auto r = f.filter(s);
    EXPECT_EQ(f.meanDistances(), (std::vector<double>{2.0, 1.5, 2.5}));
    EXPECT_EQ(r.mean_distance, 2.0);
    EXPECT_EQ(r.stddev_distance, 0.5);
    EXPECT_EQ(r.threshold, 2.5);
    EXPECT_EQ(r.points_removed, 0u);
    s = input;
    f.initialize(params(8, 0.99));
    r = f.filter(s);
    EXPECT_EQ(r.points_removed, 1u);
    EXPECT_EQ(s.valid, test::flags({1, 1, 0}));
    // k = 1: d = 1, 1, 2; mu = 4/3, sigma = sqrt(1/3): 13 is above mu + 0.5 sigma.
    s = input;
    f.initialize(params(1, 0.5));
    r = f.filter(s);
    EXPECT_EQ(f.meanDistances(), (std::vector<double>{1.0, 1.0, 2.0}));
    EXPECT_EQ(s.valid, test::flags({1, 1, 0}));
}

TEST(StatisticalOutlierFilter, TwoPointsAreAlwaysKept) {
    // Both have the same d, so sigma = 0 and d = mu = the threshold: not above it.
    for (const double m : {0.0, 1.0}) {
        StatisticalOutlierFilter f(params(8, m));
        Scan s = test::makeScan({2.0f, 7.5f}, 1.0);
        const auto r = f.filter(s);
        EXPECT_EQ(r.points_removed, 0u);
        EXPECT_EQ(r.stddev_distance, 0.0);
        EXPECT_EQ(r.threshold, r.mean_distance);
        EXPECT_GT(r.mean_distance, 5.0);
    }
}

TEST(StatisticalOutlierFilter, FewerThanTwoPointsHaveNoStatistics) {
    StatisticalOutlierFilter f(params(8, 0.0));
    Scan one = test::makeScan({2.0f});
    auto r = f.filter(one);
    EXPECT_EQ(r.points_in, 1u);
    EXPECT_EQ(r.points_removed, 0u);
    EXPECT_EQ(one.valid[0], 1);
    EXPECT_EQ(r.mean_distance, 0.0);
    EXPECT_EQ(r.threshold, 0.0);
    ASSERT_EQ(f.meanDistances().size(), 1u);
    EXPECT_TRUE(std::isnan(f.meanDistances()[0]));
    Scan none = test::emptyScan(50, kPi);
    r = f.filter(none);
    EXPECT_EQ(r.points_in, 0u);
    EXPECT_EQ(f.meanDistances().size(), 50u);
    Scan zero = test::makeScan({});
    r = f.filter(zero);
    EXPECT_EQ(r.points_in, 0u);
    EXPECT_TRUE(f.meanDistances().empty());
}

TEST(StatisticalOutlierFilter, DuplicatesBeyondKAreHandled) {
    // Twelve points at the same place (more than k + 1 = 9: a point may be pushed out of its
    // own k + 1 nearest by its copies) and one 10 m away.
    std::vector<float> ranges(12, 3.0f);
    ranges.push_back(13.0f);
    Scan s = line(ranges);
    StatisticalOutlierFilter f;
    const auto r = f.filter(s);
    for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(f.meanDistances()[i], 0.0) << i;
    EXPECT_EQ(f.meanDistances()[12], 10.0);
    EXPECT_EQ(r.points_removed, 1u);
    EXPECT_EQ(s.valid[12], 0);
}

TEST(StatisticalOutlierFilter, InvalidAndNonFiniteBeams) {
    // Invalid beams are no neighbours; valid beams without a position are removed and left
    // out of the statistics.
    const Scan clean = line({10.0f, 11.0f, 13.0f, 50.0f, 12.0f});
    Scan a = clean;
    a.valid = test::flags({1, 1, 1, 0, 0});
    Scan b = clean;
    b.range[3] = std::numeric_limits<float>::quiet_NaN();
    b.range[4] = -std::numeric_limits<float>::infinity();
    b.valid = test::flags({1, 1, 1, 1, 1});
    StatisticalOutlierFilter f(params(8, 1.0));
    const auto ra = f.filter(a);
    const auto da = f.meanDistances();
    const auto rb = f.filter(b);
    EXPECT_EQ(ra.points_in, 3u);
    EXPECT_EQ(ra.points_removed, 0u);
    EXPECT_EQ(rb.points_in, 5u);
    EXPECT_EQ(rb.points_removed, 2u);
    EXPECT_EQ(b.valid, test::flags({1, 1, 1, 0, 0}));
    EXPECT_EQ(rb.mean_distance, ra.mean_distance);
    EXPECT_EQ(rb.threshold, ra.threshold);
    EXPECT_EQ(ra.threshold, 2.5);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(f.meanDistances()[i], da[i]) << i;
    EXPECT_TRUE(std::isnan(f.meanDistances()[3]));
    EXPECT_TRUE(std::isnan(da[3]));
}

TEST(StatisticalOutlierFilter, BuffersFromALargerScanDoNotLeak) {
    StatisticalOutlierFilter f(params(6, 0.5));
    auto [big, small] = test::largeThenSmallScans();
    Scan smallCopy = small;
    f.filter(big);
    const auto r = f.filter(small);
    StatisticalOutlierFilter fresh(params(6, 0.5));
    const auto rf = fresh.filter(smallCopy);
    EXPECT_EQ(small.valid, smallCopy.valid);
    EXPECT_EQ(r.points_removed, rf.points_removed);
    EXPECT_EQ(r.threshold, rf.threshold);
    EXPECT_GT(r.points_removed, 0u);
    ASSERT_EQ(f.meanDistances().size(), 90u);
    for (std::size_t i = 0; i < 90; ++i) {
        const double a = f.meanDistances()[i], b = fresh.meanDistances()[i];
        EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << i;
    }
}

// --- As a pipeline stage --------------------------------------------------------------------

TEST(StatisticalOutlierFilter, PipelineStage) {
    Pipeline::Params p;
    p.stages = {"distance", "sor"};
    Pipeline pipe(p, test::allStages());
    ASSERT_EQ(pipe.stages().size(), 2u);
    EXPECT_STREQ(pipe.stages()[1]->name(), "sor");
    Scan scan = test::wallWithOutliers();
    auto r = pipe.process(scan);
    EXPECT_TRUE(r.keep);
    EXPECT_EQ(r.dropped_by, "");
    EXPECT_EQ(r.points_in, 181u);
    EXPECT_EQ(r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().points_in, 181u);
    EXPECT_EQ(r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().points_removed, 3u);
    EXPECT_EQ(r.noiseRemoved(), 3u);
    EXPECT_GT(r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().threshold,
              r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().mean_distance);
    EXPECT_EQ(r.points_out, 178u);
    for (const std::size_t i : {20u, 90u, 150u}) EXPECT_EQ(scan.valid[i], 0) << i;
    EXPECT_EQ(r.findOrDefault<kfd::RadiusOutlierFilter::Result>().points_in,
              0u);  // other baselines did not run
    EXPECT_EQ(r.findOrDefault<kfd::DbscanFilter::Result>().points_in, 0u);

    // Parameters reach the stage. With the far outliers gone in the distance stage, the spike
    // is the only outlier among 179 points, and a single outlier among n points is at most
    // (n - 1) / sqrt(n) sigma above the mean (13.3 here): with std_mul 20 it stays.
    p.get<kfd::DistanceStage>().max_range = 5.0;
    p.get<kfd::SorStage>() = params(8, 20.0);
    pipe.initialize(p);
    scan = test::wallWithOutliers();
    r = pipe.process(scan);
    EXPECT_EQ(r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().points_in, 179u);
    EXPECT_EQ(r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().points_removed, 0u);
    p.get<kfd::SorStage>() = params(8, 1.0);
    pipe.initialize(p);
    scan = test::wallWithOutliers();
    r = pipe.process(scan);
    EXPECT_EQ(r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().points_removed, 1u);
    EXPECT_EQ(scan.valid[90], 0);

    // Without the stage nothing is reported.
    p.stages = {"distance"};
    pipe.initialize(p);
    scan = test::wallWithOutliers();
    r = pipe.process(scan);
    EXPECT_EQ(r.findOrDefault<kfd::StatisticalOutlierFilter::Result>().points_in, 0u);
    EXPECT_EQ(r.points_out, 179u);
}

TEST(StatisticalOutlierFilter, PipelineValidatesTheStageEvenWhenUnlisted) {
    Pipeline::Params p;  // default stages: no sor
    p.get<kfd::SorStage>().k = 0;
    EXPECT_THROW(Pipeline(p, test::allStages()), kfd::ParameterError);
    p = Pipeline::Params{};
    p.get<kfd::SorStage>().std_mul = -1.0;
    EXPECT_THROW(Pipeline(p, test::allStages()), kfd::ParameterError);
    p = Pipeline::Params{};
    p.stages = {"sor", "sor"};
    EXPECT_EQ(Pipeline(p, test::allStages()).stages().size(), p.stages.size());  // twice: allowed
    p.stages = {"distance", "radius", "sor"};  // both baselines can be chained
    const Pipeline both(p, test::allStages());
    EXPECT_EQ(both.stages().size(), 3u);
}

// --- Against a plain O(n^2) statistical outlier removal --------------------------------------

struct Expected {
    std::vector<std::uint8_t> valid;
    std::vector<double> mean;  // per beam, NaN when none
    double mu = 0.0, sigma = 0.0, threshold = 0.0;
};

/// Exhaustive search with the filter's documented arithmetic: float coordinates from double
/// trigonometry, float squared distances, d_i = double sum of the square roots of the k
/// smallest (in increasing order) over their count, mu and sample sigma in beam order.
Expected plainStatisticalOutlier(const Scan& s, std::size_t k, double std_mul) {
    Expected e;
    e.valid = test::withPosition(s);
    e.mean.assign(s.size(), kNaN);
    const test::Points p = test::cartesian(s);
    const std::size_t m = p.size();
    if (m < 2) return e;
    std::vector<double> d(m);
    for (std::size_t i = 0; i < m; ++i) {
        std::vector<float> d2 = test::squaredDistancesFrom(p, i);
        const std::size_t used = std::min(k, d2.size());
        std::partial_sort(d2.begin(), d2.begin() + static_cast<std::ptrdiff_t>(used), d2.end());
        double sum = 0.0;
        for (std::size_t j = 0; j < used; ++j) sum += std::sqrt(static_cast<double>(d2[j]));
        d[i] = sum / static_cast<double>(used);
    }
    double sum = 0.0;
    for (const double v : d) sum += v;
    e.mu = sum / static_cast<double>(m);
    double sq = 0.0;
    for (const double v : d) sq += (v - e.mu) * (v - e.mu);
    e.sigma = std::sqrt(sq / static_cast<double>(m - 1));
    e.threshold = e.mu + std_mul * e.sigma;
    for (std::size_t i = 0; i < m; ++i) {
        e.mean[p.beam[i]] = d[i];
        if (d[i] > e.threshold) e.valid[p.beam[i]] = 0;
    }
    return e;
}

TEST(StatisticalOutlierFilter, ReferenceAgreesWithHandMadeCase) {
    // Guards the reference the random comparison relies on.
    const Expected e = plainStatisticalOutlier(line({10.0f, 11.0f, 13.0f}), 8, 0.99);
    EXPECT_EQ(e.mean, (std::vector<double>{2.0, 1.5, 2.5}));
    EXPECT_EQ(e.mu, 2.0);
    EXPECT_EQ(e.sigma, 0.5);
    EXPECT_EQ(e.valid, test::flags({1, 1, 0}));
}

TEST(StatisticalOutlierFilter, MatchesPlainImplementationOnRandomScans) {
    StatisticalOutlierFilter f;  // one filter for every scan: buffers are reused across sizes
    std::size_t removed = 0, kept = 0, partial = 0;
    const int kScans = 300;
    for (int seed = 1; seed <= kScans; ++seed) {
        std::mt19937 rng(static_cast<unsigned>(seed));
        const std::size_t beams = std::uniform_int_distribution<std::size_t>(2, 720)(rng);
        const double aperture = test::randomAperture(rng, beams);
        StatisticalOutlierFilter::Params p;  // every fourth scan with the defaults
        if (seed % 4 != 0) {
            p.k = std::uniform_int_distribution<std::size_t>(1, 24)(rng);
            p.std_mul = std::uniform_real_distribution<double>(0.0, 3.0)(rng);
        }
        f.initialize(p);
        Scan input = test::randomScan(rng, beams, aperture);
        if (seed % 5 == 0) test::addBeamsWithoutPosition(input);  // valid, without a position
        if (seed % 7 == 0)  // all beams on one line: exact ties and duplicates (clamped ranges)
            input.geometry.aperture = 0.0;
        Scan output = input;
        const auto res = f.filter(output);
        const Expected e = plainStatisticalOutlier(input, p.k, p.std_mul);
        SCOPED_TRACE("seed " + std::to_string(seed) + ", " + std::to_string(beams) + " beams, k " +
                     std::to_string(p.k) + ", std_mul " + std::to_string(p.std_mul));
        ASSERT_EQ(output.valid, e.valid);
        ASSERT_EQ(res.mean_distance, e.mu);
        ASSERT_EQ(res.stddev_distance, e.sigma);
        ASSERT_EQ(res.threshold, e.threshold);
        ASSERT_EQ(f.meanDistances().size(), beams);
        for (std::size_t i = 0; i < beams; ++i) {
            const double a = f.meanDistances()[i], b = e.mean[i];
            ASSERT_TRUE(a == b || (std::isnan(a) && std::isnan(b)))
                << "beam " << i << ": " << a << " vs " << b;
            ASSERT_EQ(std::memcmp(&output.range[i], &input.range[i], sizeof(float)), 0) << i;
        }
        ASSERT_EQ(res.points_in, input.countValid());
        ASSERT_EQ(res.points_removed, input.countValid() - output.countValid());
        removed += res.points_removed;
        kept += output.countValid();
        partial += res.points_removed > 0 && output.countValid() > 0;
    }
    // Not vacuous: many points go, many stay, and most scans lose some but not all.
    EXPECT_GT(removed, 3000u);
    EXPECT_GT(kept, 20000u);
    EXPECT_GT(partial, static_cast<std::size_t>(kScans / 2));
}

}  // namespace
}  // namespace kfd
