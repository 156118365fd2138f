// Removals that look like a surface (issues 37, 39) on hand-made scans, and the one-pass line fit
// against a plain two-pass one over random runs.
#include "kfd/algorithms/surface_run.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

// `s` with beams [first, last] removed; `before` gets the flags before.
std::vector<std::uint8_t> removeBeams(Scan& s, std::size_t first, std::size_t last) {
    std::vector<std::uint8_t> before = s.valid;
    for (std::size_t i = first; i <= last; ++i) s.valid[i] = 0;
    return before;
}

TEST(SurfaceRun, AStraightPieceOfWallRemovedIsFound) {
    Scan s = test::flatWall(361, test::deg2rad(120), 3.0);  // 1/3 degree per beam
    const auto before = removeBeams(s, 170, 199);           // 30 beams, ~0.52 m of wall
    const SurfaceRun r = longestRemovedSurface(s, before.data());
    EXPECT_EQ(r.beams, 30u);
    EXPECT_EQ(r.first, 170u);
    EXPECT_NEAR(
        r.length_m,
        3.0 * (std::tan(test::deg2rad(29.0 / 3 - 10.0 / 3)) - std::tan(test::deg2rad(-10.0 / 3))),
        0.02);
    EXPECT_LT(r.rms_m, 1e-4);
}

TEST(SurfaceRun, AShortRunIsNotASurface) {
    Scan s = test::flatWall(361, test::deg2rad(120), 3.0);
    const auto before = removeBeams(s, 170, 173);  // 4 beams, fewer than 5
    EXPECT_EQ(longestRemovedSurface(s, before.data()).beams, 0u);
}

TEST(SurfaceRun, SpikesAtScatteredRangesAreNotASurface) {
    Scan s = test::flatWall(361, test::deg2rad(120), 3.0);
    for (std::size_t i = 150; i < 200; ++i) s.range[i] = (i % 2) ? 1.0f : 2.5f;
    const auto before = removeBeams(s, 150, 199);
    EXPECT_EQ(longestRemovedSurface(s, before.data()).beams, 0u);
}

TEST(SurfaceRun, AKeptBeamSplitsTheRunAndAnInvalidOneDoesNot) {
    Scan s = test::flatWall(361, test::deg2rad(120), 3.0);
    s.valid[185] = 0;  // no return before: does not split
    auto before = removeBeams(s, 182, 189);
    EXPECT_EQ(longestRemovedSurface(s, before.data()).beams, 7u);
    s.valid[185] = 0;
    before[185] = 1;
    s.valid[186] = 1;  // left valid by the stage: splits into two runs of 4 and 3 beams
    EXPECT_EQ(longestRemovedSurface(s, before.data()).beams, 0u);
}

TEST(SurfaceRun, TheLongestOfTwoSurfacesIsReported) {
    Scan s = test::flatWall(361, test::deg2rad(120), 3.0);
    std::vector<std::uint8_t> before = s.valid;
    for (std::size_t i = 20; i < 60; ++i) s.valid[i] = 0;    // 40 beams, far off axis: longer
    for (std::size_t i = 170; i < 200; ++i) s.valid[i] = 0;  // 30 beams near the axis
    const SurfaceRun r = longestRemovedSurface(s, before.data());
    EXPECT_EQ(r.first, 20u);
    EXPECT_EQ(r.beams, 40u);
}

// The one-pass fit against a plain two-pass one (mean, then covariance; gaps and extent from
// the points), on random runs with noise from none to well over the tolerance.
TEST(SurfaceRun, TheOnePassFitMatchesATwoPassFitOnRandomRuns) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), dist(1.0, 8.0), level(0.0, 0.08);
    int flagged = 0, not_flagged = 0;
    for (int trial = 0; trial < 400; ++trial) {
        Scan s = test::flatWall(181, test::deg2rad(90), dist(rng));
        const double amplitude = level(rng);
        for (auto& r : s.range) r += static_cast<float>(amplitude * unit(rng));
        const auto before = removeBeams(s, 60, 120);
        const SurfaceRun got = longestRemovedSurface(s, before.data());
        std::vector<double> xs, ys;
        double mx = 0, my = 0, mean_range = 0, max_gap_excess = -1;
        for (std::size_t i = 60; i <= 120; ++i) {
            xs.push_back(s.range[i] * std::cos(s.geometry.angle(i)));
            ys.push_back(s.range[i] * std::sin(s.geometry.angle(i)));
            mx += xs.back() / 61.0;
            my += ys.back() / 61.0;
            mean_range += s.range[i] / 61.0;
            if (xs.size() > 1) {
                const double gap =
                    std::hypot(xs.back() - xs[xs.size() - 2], ys.back() - ys[ys.size() - 2]);
                const double allowed = 4.0 * s.range[i] * s.geometry.resolution() + 0.01;
                max_gap_excess = std::max(max_gap_excess, gap - allowed);
            }
        }
        double cxx = 0, cyy = 0, cxy = 0;
        for (std::size_t k = 0; k < xs.size(); ++k) {
            cxx += (xs[k] - mx) * (xs[k] - mx) / 61.0;
            cyy += (ys[k] - my) * (ys[k] - my) / 61.0;
            cxy += (xs[k] - mx) * (ys[k] - my) / 61.0;
        }
        const double rms =
            std::sqrt(0.5 * (cxx + cyy) - std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy));
        const double tol = std::max(0.02, 0.005 * mean_range);
        const bool clear_gaps = max_gap_excess<-1e-3, broken = max_gap_excess> 1e-3;
        if (rms <= tol * 0.99 && clear_gaps) {
            ASSERT_EQ(got.beams, 61u) << trial;
            EXPECT_NEAR(got.rms_m, rms, 1e-6) << trial;
            ++flagged;
        } else if (rms > tol * 1.01 || broken) {
            EXPECT_EQ(got.beams, 0u) << trial;
            ++not_flagged;
        }
    }
    EXPECT_GT(flagged, 50);
    EXPECT_GT(not_flagged, 50);
}

TEST(SurfaceRun, SparingClearsOnlyTheRunsOnALine) {
    // A denoiser wants 30 beams of wall (a line) and 10 beams alternating 1 m / 2.5 m (no line)
    // removed: the wall's flags are cleared, the scatter's stay.
    Scan s = test::flatWall(361, test::deg2rad(120), 3.0);
    for (std::size_t i = 250; i < 260; ++i) s.range[i] = (i % 2) ? 1.0f : 2.5f;
    std::vector<std::uint8_t> remove(s.range.size(), 0);
    for (std::size_t i = 170; i < 200; ++i) remove[i] = 1;
    for (std::size_t i = 250; i < 260; ++i) remove[i] = 1;
    EXPECT_EQ(spareSurfaceRuns(s, remove.data()), 30u);
    for (std::size_t i = 170; i < 200; ++i) EXPECT_EQ(remove[i], 0) << i;
    for (std::size_t i = 250; i < 260; ++i) EXPECT_EQ(remove[i], 1) << i;
}

TEST(SurfaceRun, SparingFindsRunsWhereverTheyStartAfterLongStretchesOfKeptBeams) {
    // Between runs spareSurfaceRuns skips to the next flagged beam eight at a time: runs that
    // start at the first beam, just off and on a multiple of eight, and end at the last beam
    // are all spared, and nothing else is touched.
    for (const std::size_t start : {0u, 7u, 8u, 9u, 63u, 64u, 65u}) {
        Scan s = test::flatWall(361, test::deg2rad(120), 3.0);
        std::vector<std::uint8_t> remove(s.range.size(), 0);
        for (std::size_t i = start; i < start + 12; ++i) remove[i] = 1;
        for (std::size_t i = 349; i < 361; ++i) remove[i] = 1;
        remove[200] = 2;  // any non-zero flag counts as removed
        EXPECT_EQ(spareSurfaceRuns(s, remove.data()), 24u) << start;
        for (std::size_t i = 0; i < remove.size(); ++i)
            EXPECT_EQ(remove[i], i == 200 ? 2 : 0) << start << " " << i;
    }
}

TEST(SurfaceRun, SparingAgreesWithTheRemovedSurfaceCheck) {
    // What spareSurfaceRuns leaves flagged, removed, holds no run longestRemovedSurface calls a
    // surface, on random scans with random removals.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        Scan s = test::flatWall(181, test::deg2rad(90), 1.0 + 6.0 * unit(rng));
        const double noise = 0.05 * unit(rng);
        for (auto& r : s.range) r += static_cast<float>(noise * (unit(rng) - 0.5));
        std::vector<std::uint8_t> remove(s.range.size(), 0);
        const double share = unit(rng);
        for (auto& f : remove) f = unit(rng) < share;
        spareSurfaceRuns(s, remove.data());
        const std::vector<std::uint8_t> before = s.valid;
        for (std::size_t i = 0; i < remove.size(); ++i)
            if (remove[i]) s.valid[i] = 0;
        EXPECT_EQ(longestRemovedSurface(s, before.data()).beams, 0u) << trial;
    }
}

}  // namespace
}  // namespace kfd
