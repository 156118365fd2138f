// RealNoiseInjector: labelled outliers for real scans, three models per kind.
#include "kfd/sim/real_noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <utility>
#include <vector>

#include "kfd/mrpt/config.h"
#include "kfd/sim/denoise_quality.h"
#include "kfd/sim/noisy_log.h"
#include "kfd/stages/core_stages.h"
#include "test_files.h"
#include "test_scans.h"

namespace {

using kfd::NoiseKind;
using kfd::NoiseModel;

// A room-like real scan: walls at 2-6 m with a few depth edges, some no-return beams.
kfd::Scan roomScan(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> r(361);
    float base = 3.0f;
    for (std::size_t i = 0; i < r.size(); ++i) {
        if (i % 60 == 0) base = 2.0f + 4.0f * u(rng);  // a new surface: a depth edge
        r[i] = base + 0.01f * u(rng);
    }
    kfd::Scan s = kfd::test::makeScan(r, kfd::kPi);
    for (std::size_t i = 100; i < 105; ++i) s.valid[i] = 0;  // no return
    return s;
}

struct Injected {
    kfd::Scan before, after;
    std::vector<NoiseKind> kinds;
    std::vector<NoiseModel> models;
};

std::vector<Injected> inject(const kfd::RealNoiseInjector::Params& p, int scans, unsigned seed) {
    kfd::RealNoiseInjector inj(p);
    std::mt19937 rng(seed);
    std::vector<Injected> out;
    for (int k = 0; k < scans; ++k) {
        Injected x;
        x.before = roomScan(rng);
        x.after = x.before;
        inj.apply(x.after, x.kinds, x.models, rng);
        out.push_back(std::move(x));
    }
    return out;
}

TEST(RealNoiseInjector, OnlyLabelledBeamsChangeAndEveryLabelNamesItsModel) {
    kfd::RealNoiseInjector::Params p;
    p.isolated_rate = 0.02;
    p.cluster_rate = 1.0;
    p.edge_rate = 0.8;
    std::size_t labelled = 0;
    for (const auto& x : inject(p, 50, 3)) {
        for (std::size_t i = 0; i < x.after.size(); ++i) {
            if (x.kinds[i] == NoiseKind::Clean) {
                EXPECT_EQ(x.models[i], NoiseModel::None);
                EXPECT_EQ(x.after.range[i], x.before.range[i]);
                EXPECT_EQ(x.after.valid[i], x.before.valid[i]);
            } else {
                ++labelled;
                EXPECT_EQ(kfd::kindOf(x.models[i]), x.kinds[i]);
                EXPECT_TRUE(x.after.valid[i]);
                EXPECT_TRUE(std::isfinite(x.after.range[i]));
                EXPECT_GE(x.after.range[i], p.min_range);
            }
        }
    }
    EXPECT_GT(labelled, 500u);
}

TEST(RealNoiseInjector, SpikesAndClustersLieInFrontOfTheRealReturn) {
    kfd::RealNoiseInjector::Params p;
    p.isolated_rate = 0.05;
    p.cluster_rate = 2.0;
    p.edge_rate = 0.0;
    for (const auto& x : inject(p, 40, 5))
        for (std::size_t i = 0; i < x.after.size(); ++i)
            if (x.kinds[i] != NoiseKind::Clean && x.before.valid[i]) {
                EXPECT_LT(x.after.range[i], x.before.range[i]) << toString(x.models[i]);
            }
}

TEST(RealNoiseInjector, ClustersAreBurstsOfConsecutiveBeams) {
    kfd::RealNoiseInjector::Params p;
    p.isolated_rate = 0.0;
    p.edge_rate = 0.0;
    p.cluster_rate = 0.5;
    std::size_t runs = 0;
    for (const auto& x : inject(p, 200, 7)) {
        std::size_t run = 0;
        for (std::size_t i = 0; i <= x.after.size(); ++i) {
            if (i < x.after.size() && x.kinds[i] == NoiseKind::Clustered) {
                ++run;
                continue;
            }
            if (run) {
                ++runs;
                EXPECT_LE(run, 40u);  // at most two bursts of 20 side by side
            }
            run = 0;
        }
    }
    EXPECT_GT(runs, 50u);
}

TEST(RealNoiseInjector, MixedPixelsLieBetweenTheTwoSurfacesOfAnEdge) {
    kfd::RealNoiseInjector::Params p;
    p.isolated_rate = 0.0;
    p.cluster_rate = 0.0;
    p.edge_rate = 1.0;
    std::size_t n = 0;
    for (const auto& x : inject(p, 30, 9))
        for (std::size_t i = 0; i < x.after.size(); ++i) {
            if (x.kinds[i] != NoiseKind::Edge) continue;
            ++n;
            // an edge within 3 beams, and the new range between its two surfaces
            bool between = false;
            for (std::size_t j = (i >= 3 ? i - 3 : 0); j + 1 < x.before.size() && j <= i + 3; ++j) {
                const double a = x.before.range[j], b = x.before.range[j + 1];
                if (std::abs(a - b) > p.edge_jump_m && x.after.range[i] > std::min(a, b) &&
                    x.after.range[i] < std::max(a, b) * 1.01)
                    between = true;
            }
            EXPECT_TRUE(between) << "beam " << i;
        }
    EXPECT_GT(n, 50u);
}

TEST(RealNoiseInjector, EveryModelIsDrawnAndOneCanBeChosen) {
    kfd::RealNoiseInjector::Params p;
    p.isolated_rate = 0.05;
    p.cluster_rate = 2.0;
    p.edge_rate = 1.0;
    std::vector<std::size_t> seen(kfd::kNoiseModels, 0);
    for (const auto& x : inject(p, 100, 11))
        for (auto m : x.models) ++seen[static_cast<std::size_t>(m)];
    for (std::size_t m = 1; m < kfd::kNoiseModels; ++m)
        EXPECT_GT(seen[m], 0u) << toString(static_cast<NoiseModel>(m));
    p.only = NoiseModel::SpikeNearSensor;
    for (const auto& x : inject(p, 20, 11))
        for (auto m : x.models) EXPECT_TRUE(m == NoiseModel::None || m == p.only);
}

TEST(RealNoiseInjector, TheSameSeedGivesTheSameNoise) {
    kfd::RealNoiseInjector::Params p;
    const auto a = inject(p, 10, 42), b = inject(p, 10, 42);
    for (std::size_t k = 0; k < a.size(); ++k) {
        EXPECT_EQ(a[k].after.range, b[k].after.range);
        EXPECT_EQ(a[k].models, b[k].models);
    }
}

TEST(RealNoiseInjector, BadParametersAreErrors) {
    kfd::RealNoiseInjector::Params p;
    p.isolated_rate = 1.5;
    EXPECT_THROW(kfd::RealNoiseInjector{p}, kfd::ParameterError);
    p = {};
    p.cluster_rate = -1.0;
    EXPECT_THROW(kfd::RealNoiseInjector{p}, kfd::ParameterError);
    p = {};
    p.edge_jump_m = std::nan("");
    EXPECT_THROW(kfd::RealNoiseInjector{p}, kfd::ParameterError);
}

}  // namespace

// kfd-inject's library part on a real-layout log, scored back by kfd-denoise-eval's: every
// labelled beam is counted under its model, a clean score removes nothing labelled.
namespace {

const std::string kOffice = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";

// The bundled log with kfd-inject's noise, seed 3, as DIR/noisy.rawlog (options in `o`).
kfd::NoisyLogSummary noisyOffice(const kfd::test::TempDir& dir, kfd::NoisyLogOptions& o) {
    o.input = kOffice;
    o.output = dir / "noisy.rawlog";
    o.seed = 3;
    return kfd::writeNoisyLog(o);
}

TEST(NoisyLog, LabelsMatchTheInjectedBeamsAndScoreBackPerModel) {
    namespace fs = std::filesystem;
    kfd::test::TempDir dir("kfd_noisy_");
    kfd::NoisyLogOptions o;
    const auto s = noisyOffice(dir, o);
    EXPECT_EQ(s.scans, 600u);
    EXPECT_EQ(s.labels, dir / "noisy.labels.csv");
    EXPECT_GT(s.by_kind[1] + s.by_kind[2] + s.by_kind[3], 1000u);
    kfd::Pipeline::Params p =
        kfd::loadConfigFile(std::string(KFD_SOURCE_DIR) + "/share/kfd/default.ini");
    p.stages = {"distance", "denoise"};
    const auto q = kfd::evaluateDenoising(o.output, s.labels, p);
    EXPECT_EQ(q.scans, 600u);
    for (std::size_t m = 1; m < kfd::kNoiseModels; ++m)
        EXPECT_EQ(q.noise_by_model[m], s.by_model[m]) << toString(static_cast<NoiseModel>(m));
    EXPECT_GT(q.recall(), 0.0);
    std::size_t bands = 0;
    for (auto c : q.clean_by_band) bands += c;
    EXPECT_EQ(bands, q.clean);
    // The same seed gives the same files; the output may not be the input.
    o.output = dir / "again.rawlog";
    kfd::writeNoisyLog(o);
    EXPECT_EQ(kfd::test::fileBytes(dir / "again.labels.csv"),
              kfd::test::fileBytes(dir / "noisy.labels.csv"));
    // The progress callback counts the scans read as the copy goes (kfd-inject's progress line).
    std::vector<std::pair<double, std::size_t>> calls;
    o.output = dir / "progress.rawlog";
    o.progress_every = 200;  // log entries: a scan and its odometry each
    o.on_progress = [&](double f, std::size_t scans) { calls.emplace_back(f, scans); };
    kfd::writeNoisyLog(o);
    ASSERT_GE(calls.size(), 3u);
    EXPECT_GT(calls.front().second, 0u);
    EXPECT_LT(calls.front().second, s.scans);
    for (std::size_t i = 1; i < calls.size(); ++i) {  // the last call may repeat the count
        if (i + 1 < calls.size()) {
            EXPECT_GT(calls[i].second, calls[i - 1].second);
        }
        EXPECT_GE(calls[i].second, calls[i - 1].second);
        EXPECT_GE(calls[i].first, calls[i - 1].first);
    }
    EXPECT_EQ(calls.back(), std::make_pair(1.0, s.scans));
    o.on_progress = nullptr;
    o.output = kOffice;
    EXPECT_ANY_THROW(kfd::writeNoisyLog(o));
    EXPECT_TRUE(fs::exists(kOffice));
}

}  // namespace

namespace {

// kfd-denoise-eval with next_scan (issue 25): a held keyframe is scored once finished (the
// last one at the end of the log); the same scans are scored and every labelled beam counted.
TEST(NoisyLog, WithNextScanTheSameScansAreScoredOnceFinished) {
    kfd::test::TempDir dir("kfd_noisy_next_");
    kfd::NoisyLogOptions o;
    const auto s = noisyOffice(dir, o);
    kfd::Pipeline::Params off =
        kfd::loadConfigFile(std::string(KFD_SOURCE_DIR) + "/share/kfd/default.ini");
    kfd::Pipeline::Params on = off;
    on.get<kfd::EvidenceDenoiseStage>().next_scan = true;
    const auto a = kfd::evaluateDenoising(o.output, s.labels, on);
    const auto b = kfd::evaluateDenoising(o.output, s.labels, off);
    EXPECT_EQ(a.scans, 600u);
    EXPECT_EQ(a.scored, b.scored);
    EXPECT_GT(a.scored, 1u);
    EXPECT_EQ(a.points, b.points);
    EXPECT_EQ(a.noise, b.noise);
    EXPECT_EQ(a.clean, b.clean);
    EXPECT_GT(a.removed_noise, 0u);
}

}  // namespace
