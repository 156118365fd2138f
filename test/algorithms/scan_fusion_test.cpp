#include "kfd/algorithms/scan_fusion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "kfd/algorithms/pose.h"

namespace kfd {
namespace {

// A world of line segments and a scanner (181 beams over 180 degrees unless told) in it.
struct Wall {
    double ax, ay, bx, by;
};

double castRay(const std::vector<Wall>& world, double ox, double oy, double a) {
    const double dx = std::cos(a), dy = std::sin(a);
    double best = std::numeric_limits<double>::infinity();
    for (const auto& w : world) {
        const double ex = w.bx - w.ax, ey = w.by - w.ay;
        const double den = dx * ey - dy * ex;
        if (std::abs(den) < 1e-12) continue;
        const double t = ((w.ax - ox) * ey - (w.ay - oy) * ex) / den;
        const double v = ((w.ax - ox) * dy - (w.ay - oy) * dx) / den;
        if (t > 0.0 && v >= 0.0 && v <= 1.0) best = std::min(best, t);
    }
    return best;
}

// A scan of `world` from odometry pose `pose` (sensor at the robot's origin), with Gaussian
// range noise sigma (0: exact), or the exact ranges if `rng` is null.
Scan scanOf(const std::vector<Wall>& world, const Pose2D& pose, double sigma, std::mt19937* rng,
            std::size_t beams = 181, double aperture = kPi) {
    Scan s;
    s.geometry = ScanGeometry{beams, aperture, true};
    s.range.assign(beams, 0.0f);
    s.valid.assign(beams, 0);
    std::normal_distribution<double> noise(0.0, sigma > 0.0 ? sigma : 1.0);
    for (std::size_t i = 0; i < beams; ++i) {
        const double r = castRay(world, pose.x, pose.y, pose.phi + s.geometry.angle(i));
        if (!std::isfinite(r) || r > 20.0) continue;
        s.range[i] = static_cast<float>(r + (rng && sigma > 0.0 ? noise(*rng) : 0.0));
        s.valid[i] = 1;
    }
    s.odometry = pose;
    return s;
}

// A 10 m x 8 m room around the origin with a box in it.
std::vector<Wall> room() {
    return {{-4, -3, 6, -3}, {6, -3, 6, 5},    {6, 5, -4, 5},  {-4, 5, -4, -3},
            {2, 0, 2.6, 0},  {2.6, 0, 2.6, 1}, {2.6, 1, 2, 1}, {2, 1, 2, 0}};
}

// RMS of (scan - truth) over the beams valid in both.
double rmsError(const Scan& s, const Scan& truth) {
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (s.valid[i] && truth.valid[i]) {
            const double e = s.range[i] - truth.range[i];
            sum += e * e;
            ++n;
        }
    return n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

TEST(ScanFusion, RepeatedViewsOfAStillSceneLowerTheRangeNoise) {
    std::mt19937 rng(1);
    const auto world = room();
    const Pose2D pose{0, 0, 0.3};
    ScanFusion f;
    for (int k = 0; k < 8; ++k) f.observe(scanOf(world, pose, 0.02, &rng));
    Scan kf = scanOf(world, pose, 0.02, &rng);
    const Scan truth = scanOf(world, pose, 0.0, nullptr);
    const double before = rmsError(kf, truth);
    const auto r = f.fuse(kf);
    const double after = rmsError(kf, truth);
    EXPECT_EQ(r.scans_kept, 8u);
    EXPECT_EQ(r.scans_used, 8u);
    EXPECT_GT(r.beams_fused, r.beams_valid * 8 / 10);
    EXPECT_GT(r.mean_scans_per_fused, 5.0);
    EXPECT_GT(r.sigma, 0.01);  // measured from the keyframe (true sigma 0.02 m)
    EXPECT_LT(r.sigma, 0.04);
    EXPECT_LT(after, 0.7 * before);
    EXPECT_EQ(f.kept(), 0u);  // the ring starts again after a keyframe
}

TEST(ScanFusion, DroppedScansTakenElsewhereAreMovedIntoTheKeyframesFrame) {
    std::mt19937 rng(2);
    const auto world = room();
    ScanFusion f;
    for (int k = 0; k < 6; ++k)
        f.observe(scanOf(world, Pose2D{-0.05 * k, 0.02 * k, 0.2 + 0.01 * k}, 0.02, &rng));
    const Pose2D pose{0.1, 0.0, 0.15};
    Scan kf = scanOf(world, pose, 0.02, &rng);
    const Scan truth = scanOf(world, pose, 0.0, nullptr);
    const double before = rmsError(kf, truth);
    const auto r = f.fuse(kf);
    EXPECT_EQ(r.scans_used, 6u);
    EXPECT_EQ(r.scans_misaligned, 0u);
    EXPECT_LT(rmsError(kf, truth), 0.75 * before);
}

TEST(ScanFusion, ScansWhoseOdometryIsOffTakeNoPartWithoutAlignment) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    ScanFusion::Params p;
    p.min_sigma_m = 0.005;  // the exact keyframe measures 0: sigma is the floor, gate 2.1 cm
    p.refine_iterations = 0;
    ScanFusion f(p);
    // Taken at (0.015, 0) but reporting (0, 0): the wall 1.5 cm nearer, inside the gate but
    // 3 sigma off in the median.
    for (int k = 0; k < 4; ++k) {
        Scan s = scanOf(wall, Pose2D{0.015, 0.0, 0.0}, 0.0, nullptr);
        s.odometry = Pose2D{0, 0, 0};
        f.observe(s);
    }
    Scan kf = scanOf(wall, Pose2D{0, 0, 0}, 0.0, nullptr);
    const Scan before = kf;
    const auto r = f.fuse(kf);
    EXPECT_EQ(r.scans_used, 0u);
    EXPECT_EQ(r.scans_misaligned, 4u);
    EXPECT_EQ(r.beams_fused, 0u);
    EXPECT_EQ(kf.range, before.range);
    // The same scans with their true odometry are used.
    for (int k = 0; k < 4; ++k) f.observe(scanOf(wall, Pose2D{0.015, 0.0, 0.0}, 0.0, nullptr));
    EXPECT_EQ(f.fuse(kf).scans_used, 4u);
}

TEST(ScanFusion, TheAlignmentCorrectsOdometryErrorsBeforeTheGate) {
    std::mt19937 rng(9);
    const auto world = room();
    ScanFusion::Params p;
    p.min_sigma_m = 0.005;
    ScanFusion f(p);
    // Taken at (0.03, -0.02, 0.6 deg) off what the odometry says: 3 cm, beyond the gate.
    const Pose2D pose{0.5, 0.2, 0.1};
    for (int k = 0; k < 4; ++k) {
        Scan s = scanOf(world, Pose2D{pose.x + 0.03, pose.y - 0.02, pose.phi + 0.01}, 0.005, &rng);
        s.odometry = pose;
        f.observe(s);
    }
    Scan kf = scanOf(world, pose, 0.005, &rng);
    const Scan truth = scanOf(world, pose, 0.0, nullptr);
    const double before = rmsError(kf, truth);
    const auto r = f.fuse(kf);
    EXPECT_EQ(r.scans_refined, 4u);
    EXPECT_EQ(r.scans_used, 4u);
    EXPECT_GT(r.beams_fused, r.beams_valid / 2);
    EXPECT_LT(rmsError(kf, truth), 0.8 * before);
}

TEST(ScanFusion, ReturnsOfAnotherSurfaceAreNotFused) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    ScanFusion::Params p;
    p.min_sigma_m = 0.01;
    ScanFusion f(p);
    std::mt19937 rng(4);
    // The dropped scans see a person at 1 m over beams 85-95; the keyframe sees the wall.
    for (int k = 0; k < 4; ++k) {
        Scan s = scanOf(wall, Pose2D{}, 0.005, &rng);
        for (std::size_t i = 85; i <= 95; ++i) s.range[i] = 1.0f;
        f.observe(s);
    }
    Scan kf = scanOf(wall, Pose2D{}, 0.005, &rng);
    const Scan before = kf;
    const auto r = f.fuse(kf);
    EXPECT_EQ(r.scans_used, 4u);
    EXPECT_GT(r.beams_fused, 100u);
    for (std::size_t i = 86; i <= 94; ++i) EXPECT_EQ(kf.range[i], before.range[i]) << i;
    EXPECT_NE(kf.range[50], before.range[50]);
}

TEST(ScanFusion, InvalidBeamsStayInvalidAndKeepTheirRange) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    std::mt19937 rng(5);
    ScanFusion f;
    for (int k = 0; k < 4; ++k) f.observe(scanOf(wall, Pose2D{}, 0.01, &rng));
    Scan kf = scanOf(wall, Pose2D{}, 0.01, &rng);
    kf.valid[40] = 0;
    kf.range[40] = 0.0f;
    const auto r = f.fuse(kf);
    EXPECT_GT(r.beams_fused, 0u);
    EXPECT_EQ(kf.valid[40], 0);
    EXPECT_EQ(kf.range[40], 0.0f);
    EXPECT_EQ(r.beams_valid, kf.countValid());
}

TEST(ScanFusion, TooFewAgreeingReturnsLeaveTheBeam) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    std::mt19937 rng(6);
    ScanFusion::Params p;
    p.min_agreeing = 3;
    ScanFusion f(p);
    for (int k = 0; k < 2; ++k) f.observe(scanOf(wall, Pose2D{}, 0.01, &rng));
    Scan kf = scanOf(wall, Pose2D{}, 0.01, &rng);
    const Scan before = kf;
    const auto r = f.fuse(kf);
    EXPECT_EQ(r.scans_used, 2u);
    EXPECT_EQ(r.beams_fused, 0u);
    EXPECT_EQ(kf.range, before.range);
}

TEST(ScanFusion, LaserOnlyFusesNothing) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    std::mt19937 rng(7);
    ScanFusion f;
    for (int k = 0; k < 4; ++k) {
        Scan s = scanOf(wall, Pose2D{}, 0.01, &rng);
        s.odometry.reset();
        f.observe(s);
    }
    EXPECT_EQ(f.kept(), 0u);
    Scan kf = scanOf(wall, Pose2D{}, 0.01, &rng);
    kf.odometry.reset();
    const Scan before = kf;
    EXPECT_EQ(f.fuse(kf).beams_fused, 0u);
    EXPECT_EQ(kf.range, before.range);
}

TEST(ScanFusion, NothingIsFusedAcrossAResetOrANewGeometry) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    std::mt19937 rng(8);
    ScanFusion f;
    for (int k = 0; k < 4; ++k) f.observe(scanOf(wall, Pose2D{}, 0.01, &rng));
    f.reset();
    Scan kf = scanOf(wall, Pose2D{}, 0.01, &rng);
    EXPECT_EQ(f.fuse(kf).scans_kept, 0u);
    // Kept scans of 181 beams, then one of 361: the ring holds only the new one.
    for (int k = 0; k < 4; ++k) f.observe(scanOf(wall, Pose2D{}, 0.01, &rng));
    f.observe(scanOf(wall, Pose2D{}, 0.01, &rng, 361));
    EXPECT_EQ(f.kept(), 1u);
    // A keyframe of another geometry than the kept scans fuses nothing.
    Scan other = scanOf(wall, Pose2D{}, 0.01, &rng, 181);
    const Scan before = other;
    const auto r = f.fuse(other);
    EXPECT_EQ(r.scans_used, 0u);
    EXPECT_EQ(other.range, before.range);
}

TEST(ScanFusion, TheRingKeepsTheNewestScans) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    ScanFusion::Params p;
    p.max_scans = 2;
    p.min_agreeing = 1;
    ScanFusion f(p);
    // Three old scans 5 cm off (outside the gate), then two exact ones: only those two count.
    for (int k = 0; k < 3; ++k) {
        Scan s = scanOf(wall, Pose2D{}, 0.0, nullptr);
        for (auto& r : s.range) r += 0.05f;
        f.observe(s);
    }
    for (int k = 0; k < 2; ++k) f.observe(scanOf(wall, Pose2D{}, 0.0, nullptr));
    EXPECT_EQ(f.kept(), 2u);
    Scan kf = scanOf(wall, Pose2D{}, 0.0, nullptr);
    const auto r = f.fuse(kf);
    EXPECT_EQ(r.scans_used, 2u);
    EXPECT_DOUBLE_EQ(r.mean_scans_per_fused, 2.0);
}

TEST(ScanFusion, FarDroppedScansAreNotUsed) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    ScanFusion f;
    for (int k = 0; k < 3; ++k) f.observe(scanOf(wall, Pose2D{-1.5, 0, 0}, 0.0, nullptr));
    Scan kf = scanOf(wall, Pose2D{}, 0.0, nullptr);
    EXPECT_EQ(f.fuse(kf).scans_used, 0u);
}

TEST(ScanFusion, MeanEstimatorAveragesTheAgreeingReturnsAndMedianTakesTheMiddle) {
    const std::vector<Wall> wall = {{3, -10, 3, 10}};
    const Scan exact = scanOf(wall, Pose2D{}, 0.0, nullptr);
    // Two dropped scans +-6 mm and +-12 mm off by beam parity (no bias); the keyframe exact but
    // 3 cm long at beam 90: its returns there are 3.03, 3.006 and 3.012 (gate 4.2 cm).
    auto fused = [&](ScanFusion::Estimator e) {
        ScanFusion::Params p;
        p.estimator = e;
        p.min_sigma_m = 0.01;
        p.max_bias_sigmas = 2.0;
        p.refine_iterations = 0;  // the zig-zag offsets would move the alignment
        ScanFusion f(p);
        for (const float off : {0.006f, 0.012f}) {
            Scan s = exact;
            for (std::size_t i = 0; i < s.size(); ++i) s.range[i] += i % 2 ? -off : off;
            f.observe(s);
        }
        Scan kf = exact;
        kf.range[90] += 0.03f;
        EXPECT_EQ(f.fuse(kf).scans_used, 2u);
        return kf.range[90] - exact.range[90];
    };
    EXPECT_NEAR(fused(ScanFusion::Estimator::Mean), 0.016f, 1e-4);
    EXPECT_NEAR(fused(ScanFusion::Estimator::Median), 0.012f, 1e-4);
}

TEST(ScanFusion, BadParametersThrowNamingTheField) {
    auto field = [](auto change) {
        ScanFusion::Params p;
        change(p);
        try {
            ScanFusion f(p);
        } catch (const ParameterError& e) {
            return e.field();
        }
        return std::string("none");
    };
    EXPECT_EQ(field([](auto& p) { p.max_scans = 0; }), "max_scans");
    EXPECT_EQ(field([](auto& p) { p.max_scans = 65; }), "max_scans");
    EXPECT_EQ(field([](auto& p) { p.min_agreeing = 9; }), "min_agreeing");
    EXPECT_EQ(field([](auto& p) { p.gate_sigmas = 0.0; }), "gate_sigmas");
    EXPECT_EQ(field([](auto& p) { p.max_bias_sigmas = std::nan(""); }), "max_bias_sigmas");
    EXPECT_EQ(field([](auto& p) { p.min_sigma_m = -1.0; }), "min_sigma_m");
    EXPECT_EQ(field([](auto& p) { p.max_step_m = 0.0; }), "max_step_m");
    EXPECT_EQ(field([](auto& p) { p.max_step_deg = 181.0; }), "max_step_deg");
    EXPECT_EQ(field([](auto& p) { p.max_span_beams = 0; }), "max_span_beams");
    EXPECT_EQ(field([](auto& p) { p.refine_iterations = 21; }), "refine_iterations");
    EXPECT_EQ(field([](auto& p) { p.refine_samples = 4; }), "refine_samples");
    EXPECT_EQ(field([](auto& p) { p.refine_gate_m = 0.0; }), "refine_gate_m");
    EXPECT_EQ(field([](auto&) {}), "none");
}

// The plain reference: every beam against every segment of every scan, in double, with libm's
// atan2, the same rules as ScanFusion (breakpoint, span, gate, bias, median).
std::vector<float> referenceFuse(const std::vector<Scan>& dropped, const Scan& kf, double sigma,
                                 const ScanFusion::Params& p) {
    const std::size_t n = kf.size();
    const double gate = p.gate_sigmas * std::sqrt(2.0) * sigma;
    const double noise = 3.0 * std::sqrt(2.0) * sigma;
    const double res = kf.geometry.resolution(), lambda = 10.0 * kPi / 180.0;
    const double dt = std::min(res, 0.5 * lambda);
    const double factor = std::sin(dt) / std::sin(lambda - dt);
    const Pose2D kp = *kf.odometry;
    std::vector<std::vector<double>> cand(
        dropped.size(), std::vector<double>(n, std::numeric_limits<double>::infinity()));
    std::vector<bool> used(dropped.size(), false);
    for (std::size_t s = 0; s < dropped.size(); ++s) {
        const Scan& d = dropped[s];
        const Pose2D rel = between(kp, *d.odometry);
        auto point = [&](std::size_t j, double& x, double& y, double& u) {
            const double a = d.geometry.angle(j), r = d.range[j];
            const double px = r * std::cos(a), py = r * std::sin(a);
            x = std::cos(rel.phi) * px - std::sin(rel.phi) * py + rel.x;
            y = std::sin(rel.phi) * px + std::cos(rel.phi) * py + rel.y;
            u = (std::atan2(y, x) - kf.geometry.angle(0)) / kf.geometry.step();
        };
        for (std::size_t k = 0; k < n; ++k) {
            const double ca = std::cos(kf.geometry.angle(k)), sa = std::sin(kf.geometry.angle(k));
            for (std::size_t j = 0; j + 1 < n; ++j) {
                if (!d.valid[j] || !d.valid[j + 1]) continue;
                double x0, y0, u0, x1, y1, u1;
                point(j, x0, y0, u0);
                point(j + 1, x1, y1, u1);
                const double ex = x1 - x0, ey = y1 - y0;
                const double dmax = std::min(d.range[j], d.range[j + 1]) * factor + noise;
                if (std::hypot(ex, ey) > dmax) continue;
                const double ua = std::min(u0, u1), ub = std::max(u0, u1);
                if (ub - ua > static_cast<double>(p.max_span_beams)) continue;
                const double kk = static_cast<double>(k);
                if (kk < ua || kk > ub) continue;
                const double t = (x0 * ey - y0 * ex) / (ca * ey - sa * ex);
                if (t > 0.0) cand[s][k] = std::min(cand[s][k], t);
            }
        }
        std::vector<double> diffs;
        for (std::size_t k = 0; k < n; ++k)
            if (kf.valid[k] && std::abs(cand[s][k] - kf.range[k]) <= gate)
                diffs.push_back(cand[s][k] - kf.range[k]);
        if (diffs.size() < 16) continue;
        std::sort(diffs.begin(), diffs.end());
        used[s] = std::abs(diffs[diffs.size() / 2]) <= p.max_bias_sigmas * sigma;
    }
    std::vector<float> out = kf.range;
    for (std::size_t k = 0; k < n; ++k) {
        if (!kf.valid[k]) continue;
        std::vector<double> v{kf.range[k]};
        for (std::size_t s = 0; s < dropped.size(); ++s)
            if (used[s] && std::abs(cand[s][k] - kf.range[k]) <= gate) v.push_back(cand[s][k]);
        if (v.size() - 1 < p.min_agreeing) continue;
        std::sort(v.begin(), v.end());
        const std::size_t m = v.size();
        out[k] = static_cast<float>(m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]));
    }
    return out;
}

TEST(ScanFusion, MatchesThePlainReferenceOnRandomScenes) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    std::size_t compared = 0, differ = 0, fused = 0;
    for (int trial = 0; trial < 20; ++trial) {
        // A random room with three random boxes; random small motions between the scans.
        std::vector<Wall> world = room();
        for (int b = 0; b < 3; ++b) {
            const double cx = 3.0 * U(rng), cy = 2.0 * U(rng) + 1.0, h = 0.2 + 0.2 * (U(rng) + 1);
            world.push_back({cx - h, cy - h, cx + h, cy - h});
            world.push_back({cx + h, cy - h, cx + h, cy + h});
            world.push_back({cx + h, cy + h, cx - h, cy + h});
            world.push_back({cx - h, cy + h, cx - h, cy - h});
        }
        const Pose2D kp{0.3 * U(rng), 0.3 * U(rng) - 1.5, 0.3 * U(rng)};
        ScanFusion::Params p;
        p.max_scans = 6;
        p.refine_iterations = 0;  // the reference moves the scans by odometry only
        ScanFusion f(p);
        std::vector<Scan> dropped;
        const int nd = 2 + trial % 5;
        for (int k = 0; k < nd; ++k) {
            const Pose2D dp{kp.x + 0.1 * U(rng), kp.y + 0.1 * U(rng), kp.phi + 0.05 * U(rng)};
            Scan s = scanOf(world, dp, 0.01, &rng);
            for (std::size_t i = 0; i < s.size(); ++i)
                if (rng() % 20 == 0) s.valid[i] = 0;  // dropouts
            f.observe(s);
            dropped.push_back(s);
        }
        Scan kf = scanOf(world, kp, 0.01, &rng);
        const Scan raw = kf;
        const auto r = f.fuse(kf);
        const auto ref = referenceFuse(dropped, raw, r.sigma, p);
        fused += r.beams_fused;
        for (std::size_t k = 0; k < kf.size(); ++k) {
            if (!raw.valid[k]) continue;
            ++compared;
            if (std::abs(kf.range[k] - ref[k]) > 1e-4f) ++differ;
        }
    }
    EXPECT_GT(compared, 2000u);
    EXPECT_GT(fused, compared / 2);  // the comparison covers fused beams, not only kept ones
    // float vs double and the approximate atan2 may flip a beam at a segment's end.
    EXPECT_LE(differ, compared / 200) << differ << " of " << compared;
}

}  // namespace
}  // namespace kfd
