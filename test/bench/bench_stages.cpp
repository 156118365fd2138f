// kfd_bench_stages: the cost of each per-scan stage on 1081-beam, 270-degree scans (the class
// of the paper's MIT data), the paper's 0.752 m/s setting (m = 8, n = 20), and the baselines
// on the same scans. Scans: bench_scans.h (ray-cast office floor, fixed seed).
//
// Stages that invalidate points get a fresh copy of the scan's valid flags before each call
// (1081 bytes, BM_RestoreValid measures it) so every iteration does the same work.
#include <benchmark/benchmark.h>

#include <cstddef>
#include <string>
#include <vector>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/slam/CICP.h>

#include "bench_scans.h"
#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/algorithms/scan_tracker.h"
#include "kfd/baselines/dbscan.h"
#include "kfd/baselines/radius_outlier.h"
#include "kfd/baselines/statistical_outlier.h"
#include "kfd/paper/correlation.h"
#include "kfd/paper/distance_filter.h"
#include "kfd/paper/histogram.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/stages/core_stages.h"

namespace {

using kfd::Scan;
namespace kb = kfd::bench;

const kb::Scenario& scenario() {
    static const kb::Scenario s = kb::makeScenario();
    return s;
}

void perScan(benchmark::State& state) {
    state.SetItemsProcessed(state.iterations());  // items = scans
    state.counters["beams"] = static_cast<double>(kb::kBeams);
}

// Runs `filter(scan)` (returns the points it removed) on the keyframe set in turn, restoring
// valid flags before each call.
template <class Filter>
void runOn(benchmark::State& state, const std::vector<Scan>& pristine, Filter&& filter) {
    std::vector<Scan> work = pristine;
    double removed = 0.0;
    std::size_t k = 0;
    for (auto _ : state) {
        Scan& s = work[k];
        kb::restoreValid(pristine[k], s);
        const std::size_t r = filter(s);
        benchmark::DoNotOptimize(r);
        removed += static_cast<double>(r);
        k = (k + 1) % work.size();
    }
    perScan(state);
    state.counters["removed"] = benchmark::Counter(removed, benchmark::Counter::kAvgIterations);
}

template <class Filter>
void runOnKeyframes(benchmark::State& state, Filter&& filter) {
    runOn(state, scenario().keyframes, filter);
}

// The loop keyframes, in order around the closed loop: the evidence denoiser always has its
// previous keyframe (temporal evidence on every scan).
template <class Filter>
void runOnLoop(benchmark::State& state, Filter&& filter) {
    runOn(state, scenario().loop_keyframes, filter);
}

void BM_RestoreValid(benchmark::State& state) {
    const auto& pristine = scenario().keyframes;
    std::vector<Scan> work = pristine;
    std::size_t k = 0;
    for (auto _ : state) {
        kb::restoreValid(pristine[k], work[k]);
        benchmark::DoNotOptimize(work[k].valid.data());
        benchmark::ClobberMemory();
        k = (k + 1) % work.size();
    }
    perScan(state);
}
BENCHMARK(BM_RestoreValid);

// Algorithm 1.
void BM_DistanceFilter(benchmark::State& state) {
    const kfd::DistanceFilter f(kb::paperParams().get<kfd::DistanceStage>());
    runOnKeyframes(state, [&](Scan& s) {
        const auto r = f.filter(s);
        return r.removed_non_finite + r.removed_out_of_range;
    });
}
BENCHMARK(BM_DistanceFilter)->Unit(benchmark::kMicrosecond);

// Sec. 3.1.2: n = 20 bins of mean range.
void BM_Histogram(benchmark::State& state) {
    const auto& scans = scenario().keyframes;
    const kfd::Histogram h(kfd::Histogram::Params{20});
    std::vector<double> out;
    std::size_t k = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(h.compute(scans[k], out));
        benchmark::ClobberMemory();
        k = (k + 1) % scans.size();
    }
    perScan(state);
}
BENCHMARK(BM_Histogram)->Unit(benchmark::kMicrosecond);

// Formula 2: one Pearson correlation of two 20-bin histograms (a decision needs m = 8).
void BM_Pearson(benchmark::State& state) {
    const auto& scans = scenario().keyframes;
    const kfd::Histogram h(kfd::Histogram::Params{20});
    std::vector<std::vector<double>> hist(scans.size());
    for (std::size_t k = 0; k < scans.size(); ++k) h.compute(scans[k], hist[k]);
    std::size_t k = 0;
    for (auto _ : state) {
        const auto& a = hist[k];
        const auto& b = hist[(k + 1) % hist.size()];
        benchmark::DoNotOptimize(kfd::pearson(a.data(), b.data(), a.size()));
        k = (k + 1) % hist.size();
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Pearson);

// Sec. 3.1.4, Formula 3: histogram + m = 8 correlations + decision, on scans the full window
// drops (the paper's 0.233 ms per dropped scan).
void BM_KeyframeDecision(benchmark::State& state) {
    const auto& sc = scenario();
    kfd::KeyframeSelector sel(kb::paperParams().get<kfd::KeyframeStage>());
    for (const auto& s : sc.prefix) sel.filter(s);
    std::size_t k = 0, kept = 0;
    for (auto _ : state) {
        const auto d = sel.filter(sc.dropped[k]);
        kept += d.keyframe ? 1 : 0;
        k = (k + 1) % sc.dropped.size();
    }
    if (kept) state.SkipWithError("a scan of the dropped set was kept: scenario broken");
    perScan(state);
    state.counters["references"] = static_cast<double>(sel.windowSize());
}
BENCHMARK(BM_KeyframeDecision)->Unit(benchmark::kMicrosecond);

// kfd's view selector (issue 12) on the same dropped scans: with odometry (arg 0) and laser
// only (arg 1); every threshold out of reach, so the keyframe stays the same.
void BM_KeyframeView(benchmark::State& state) {
    const auto& sc = scenario();
    const bool laser_only = state.range(0) == 1;
    state.SetLabel(laser_only ? "laser only" : "odometry");
    std::vector<Scan> scans;
    for (const auto& s : sc.dropped) scans.push_back(laser_only ? kb::laserOnly(s) : s);
    kfd::ViewKeyframeSelector sel(kb::viewParamsThatDrop());
    sel.filter(laser_only ? kb::laserOnly(sc.prefix.back()) : sc.prefix.back());
    std::size_t k = 0, kept = 0;
    for (auto _ : state) {
        kept += sel.filter(scans[k]).keyframe ? 1 : 0;
        k = (k + 1) % scans.size();
    }
    if (kept) state.SkipWithError("a scan was kept: scenario broken");
    perScan(state);
}
BENCHMARK(BM_KeyframeView)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// kfd's scan tracker (issue 35, the track stage's algorithm, default parameters) on the same
// dropped scans, each aligned to the last scan of the prefix (its keyframe).
void BM_Tracker(benchmark::State& state) {
    const auto& sc = scenario();
    kfd::ScanTracker tracker;
    tracker.track(sc.prefix.back());
    tracker.accept();
    std::size_t k = 0, tracked = 0;
    for (auto _ : state) {
        tracked += tracker.track(sc.dropped[k]).tracked() ? 1 : 0;
        k = (k + 1) % sc.dropped.size();
    }
    state.counters["tracked_share"] =
        benchmark::Counter(double(tracked), benchmark::Counter::kAvgIterations);
    perScan(state);
}
BENCHMARK(BM_Tracker)->Unit(benchmark::kMicrosecond);

// MRPT's ICP as kfd-icp-slam runs it on every scan (the [ICP] section of share/kfd-icp-slam/
// sick-180-5hz-every-scan.ini): the same dropped scans' points built and aligned, from their
// odometry, to a local point map of the prefix scans. icp-slam also inserts kept scans into
// its map, which this leaves out.
void BM_IcpMrpt(benchmark::State& state) {
    const auto& sc = scenario();
    mrpt::slam::CICP icp;
    icp.options.loadFromConfigFile(
        mrpt::config::CConfigFile(std::string(KFD_SOURCE_DIR) +
                                  "/share/kfd-icp-slam/sick-180-5hz-every-scan.ini"),
        "ICP");
    mrpt::maps::CSimplePointsMap local;
    for (const auto& s : sc.prefix) {
        const kfd::Pose2D p = s.odometry.value_or(kfd::Pose2D{});
        local.insertObservation(kb::toMrpt(s),
                                mrpt::poses::CPose3D(p.x, p.y, 0.0, p.phi, 0.0, 0.0));
    }
    std::vector<mrpt::obs::CObservation2DRangeScan> obs;
    for (const auto& s : sc.dropped) obs.push_back(kb::toMrpt(s));
    std::size_t k = 0;
    double iterations = 0.0;
    for (auto _ : state) {
        mrpt::maps::CSimplePointsMap points;
        points.insertObservation(obs[k]);
        const kfd::Pose2D g = sc.dropped[k].odometry.value_or(kfd::Pose2D{});
        mrpt::slam::CICP::TReturnInfo info;
        auto pdf = icp.Align(&local, &points, mrpt::poses::CPose2D(g.x, g.y, g.phi), info);
        benchmark::DoNotOptimize(pdf);
        iterations += double(info.nIterations);
        k = (k + 1) % obs.size();
    }
    state.counters["icp_iterations"] =
        benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
    perScan(state);
}
BENCHMARK(BM_IcpMrpt)->Unit(benchmark::kMicrosecond);

// Algorithm 2 as published (t = 5 rings, theta = 10 x resolution) + the m_threshold = 10
// cluster filter.
void BM_DenoiseReference(benchmark::State& state) {
    kb::StageFilter<kfd::DenoiseStage> d(
        kb::paperParams(kfd::DenoiseVariant::Reference).get<kfd::DenoiseStage>());
    runOnKeyframes(state, [&](Scan& s) { return d.filter(s).points_removed; });
}
BENCHMARK(BM_DenoiseReference)->Unit(benchmark::kMicrosecond);

// kfd's range-aware clustering + range-adaptive cluster filter (default.ini's values).
void BM_DenoiseRangeAware(benchmark::State& state) {
    kb::StageFilter<kfd::RangeAwareDenoiseStage> d(
        kb::paperParams(kfd::DenoiseVariant::RangeAware).get<kfd::RangeAwareDenoiseStage>());
    runOnKeyframes(state, [&](Scan& s) { return d.filter(s).points_removed; });
}
BENCHMARK(BM_DenoiseRangeAware)->Unit(benchmark::kMicrosecond);

// kfd's default denoiser, on the loop keyframes (DBSCAN on the same scans below).
void BM_DenoiseEvidence(benchmark::State& state) {
    kb::StageFilter<kfd::EvidenceDenoiseStage> d(
        kb::paperParams(kfd::DenoiseVariant::Evidence).get<kfd::EvidenceDenoiseStage>());
    runOnLoop(state, [&](Scan& s) { return d.filter(s).points_removed; });
}
BENCHMARK(BM_DenoiseEvidence)->Unit(benchmark::kMicrosecond);

void BM_DbscanLoop(benchmark::State& state) {
    kfd::DbscanFilter f(kfd::DbscanFilter::Params{0.7, 10});
    runOnLoop(state, [&](Scan& s) { return f.filter(s).points_removed; });
}
BENCHMARK(BM_DbscanLoop)->Unit(benchmark::kMicrosecond);

// The paper's DBSCAN comparison (Eps 0.7 m, minPts 10), on the same scans as the denoisers.
void BM_Dbscan(benchmark::State& state) {
    kfd::DbscanFilter f(kfd::DbscanFilter::Params{0.7, 10});
    runOnKeyframes(state, [&](Scan& s) { return f.filter(s).points_removed; });
}
BENCHMARK(BM_Dbscan)->Unit(benchmark::kMicrosecond);

// Baselines with kfd's default parameters, on the same scans.
void BM_RadiusOutlier(benchmark::State& state) {
    kfd::RadiusOutlierFilter f(kfd::RadiusOutlierFilter::Params{});
    runOnKeyframes(state, [&](Scan& s) { return f.filter(s).points_removed; });
}
BENCHMARK(BM_RadiusOutlier)->Unit(benchmark::kMicrosecond);

void BM_StatisticalOutlier(benchmark::State& state) {
    kfd::StatisticalOutlierFilter f(kfd::StatisticalOutlierFilter::Params{});
    runOnKeyframes(state, [&](Scan& s) { return f.filter(s).points_removed; });
}
BENCHMARK(BM_StatisticalOutlier)->Unit(benchmark::kMicrosecond);

// The whole per-scan call, Pipeline::process (distance -> keyframe -> denoise), when the
// keyframe stage drops the scan.
void BM_PipelineDropped(benchmark::State& state) {
    const auto& sc = scenario();
    kfd::Pipeline p(kb::paperParams());
    for (Scan s : sc.prefix) p.process(s);
    std::vector<Scan> work = sc.dropped;
    std::size_t k = 0, kept = 0;
    for (auto _ : state) {
        Scan& s = work[k];
        kb::restoreValid(sc.dropped[k], s);
        const auto r = p.process(s);
        kept += r.keep ? 1 : 0;
        k = (k + 1) % work.size();
    }
    if (kept) state.SkipWithError("a scan of the dropped set was kept: scenario broken");
    perScan(state);
}
BENCHMARK(BM_PipelineDropped)->Unit(benchmark::kMicrosecond);

// The whole per-scan call when the scan is a keyframe and gets denoised (arg: 0 = reference
// variant as in the paper, 1 = range-aware).
void BM_PipelineKeyframe(benchmark::State& state) {
    const auto variant =
        state.range(0) == 0 ? kfd::DenoiseVariant::Reference : kfd::DenoiseVariant::RangeAware;
    state.SetLabel(kfd::toString(variant));
    const auto& pristine = scenario().keyframes;
    kfd::Pipeline p(kb::paperParams(variant));
    std::vector<Scan> work = pristine;
    for (Scan s : pristine) p.process(s);  // fill the window, size the buffers
    std::size_t k = 0, dropped = 0;
    for (auto _ : state) {
        Scan& s = work[k];
        kb::restoreValid(pristine[k], s);
        const auto r = p.process(s);
        dropped += r.keep ? 0 : 1;
        k = (k + 1) % work.size();
    }
    if (dropped) state.SkipWithError("a scan of the keyframe set was dropped: scenario broken");
    perScan(state);
}
BENCHMARK(BM_PipelineKeyframe)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
