// kfd/sim/noise_injector.h: the three labelled outlier kinds.
#include <gtest/gtest.h>

#include <random>

#include "kfd/sim/noise_injector.h"
#include "test_scans.h"

using kfd::NoiseInjector;
using kfd::NoiseKind;

namespace {

// All beams at range r over 270 degrees.
kfd::Scan wall(std::size_t beams, double r) { return kfd::test::arc(beams, 1.5 * kfd::kPi, r); }

NoiseInjector::Params none() {
    NoiseInjector::Params p;
    p.isolated_rate = 0;
    p.cluster_rate = 0;
    p.edge_rate = 0;
    return p;
}

}  // namespace

TEST(NoiseInjector, ZeroRatesChangeNothing) {
    auto s = wall(500, 4.0);
    const auto before = s.range;
    std::vector<NoiseKind> labels;
    std::mt19937 rng(3);
    NoiseInjector(none()).apply(s, labels, rng);
    EXPECT_EQ(s.range, before);
    for (auto k : labels) EXPECT_EQ(k, NoiseKind::Clean);
}

TEST(NoiseInjector, IsolatedOutliersLieInFrontOfTheSurface) {
    auto p = none();
    p.isolated_rate = 1.0;
    auto s = wall(300, 5.0);
    std::vector<NoiseKind> labels;
    std::mt19937 rng(4);
    NoiseInjector(p).apply(s, labels, rng);
    for (std::size_t i = 0; i < s.size(); ++i) {
        EXPECT_EQ(labels[i], NoiseKind::Isolated);
        EXPECT_GE(s.range[i], p.min_range);
        EXPECT_LT(s.range[i], 5.0);
    }
}

TEST(NoiseInjector, ClusterIsARunOfBeamsNearTheSensor) {
    auto p = none();
    p.cluster_rate = 1.0;
    auto s = wall(400, 6.0);
    std::vector<NoiseKind> labels;
    std::mt19937 rng(5);
    NoiseInjector(p).apply(s, labels, rng);
    std::size_t first = s.size(), last = 0, count = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (labels[i] != NoiseKind::Clustered) continue;
        first = std::min(first, i);
        last = i;
        ++count;
        EXPECT_GE(s.range[i], 0.2 - 0.03);
        EXPECT_LE(s.range[i], p.cluster_max_range + 0.03);
    }
    EXPECT_GE(count, p.cluster_min_beams);
    EXPECT_LE(count, p.cluster_max_beams);
    EXPECT_EQ(last - first + 1, count);  // consecutive
}

TEST(NoiseInjector, EdgeOutliersLieBetweenTheTwoSurfaces) {
    auto p = none();
    p.edge_rate = 1.0;
    auto s = wall(200, 5.0);
    for (std::size_t i = 0; i < 100; ++i) s.range[i] = 2.0f;  // a near object, then the wall
    std::vector<NoiseKind> labels;
    std::mt19937 rng(6);
    NoiseInjector(p).apply(s, labels, rng);
    std::size_t edges = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (labels[i] != NoiseKind::Edge) continue;
        ++edges;
        EXPECT_GE(i, 100u);  // on the far side of the edge
        EXPECT_LE(i, 101u);
        EXPECT_GT(s.range[i], 2.0);
        EXPECT_LT(s.range[i], 5.0);
    }
    EXPECT_GE(edges, 1u);
}

TEST(NoiseInjector, SameSeedSameNoise) {
    NoiseInjector inj;  // default rates
    auto a = wall(1081, 3.0), b = wall(1081, 3.0), c = wall(1081, 3.0);
    std::vector<NoiseKind> la, lb, lc;
    std::mt19937 r1(9), r2(9), r3(10);
    inj.apply(a, la, r1);
    inj.apply(b, lb, r2);
    inj.apply(c, lc, r3);
    EXPECT_EQ(a.range, b.range);
    EXPECT_EQ(la, lb);
    EXPECT_NE(a.range, c.range);
}

TEST(NoiseInjector, InvalidParamsThrow) {
    auto p = none();
    p.isolated_rate = 1.5;
    EXPECT_THROW(NoiseInjector{p}, kfd::ParameterError);
    p = none();
    p.cluster_min_beams = 5;
    p.cluster_max_beams = 4;
    EXPECT_THROW(NoiseInjector{p}, kfd::ParameterError);
}
