// kfd_bench_instructions: the per-scan calls of kfd_bench_stages, each behind its own
// non-inlined extern "C" function kfd_ir_<case>, for instruction counts under callgrind
// (deterministic, unlike wall time on a shared machine):
//
//   valgrind --tool=callgrind --callgrind-out-file=cg.out kfd_bench_instructions 160
//   callgrind_annotate --inclusive=yes cg.out | grep kfd_ir_
//
// Each case first runs one untimed cycle over its scans (buffers sized, window filled), then
// calls its kfd_ir_ function N times; instructions per scan = inclusive cost / N. Restoring the
// valid flags between calls happens outside the counted functions. scripts/bench/bench.sh does
// all of this. Without valgrind the program just runs the cases (a smoke test).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench_scans.h"
#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/algorithms/scan_tracker.h"
#include "kfd/baselines/dbscan.h"
#include "kfd/baselines/radius_outlier.h"
#include "kfd/baselines/shadow_filter.h"
#include "kfd/baselines/speckle_filter.h"
#include "kfd/baselines/statistical_outlier.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/paper/correlation.h"
#include "kfd/paper/distance_filter.h"
#include "kfd/paper/histogram.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/stages/core_stages.h"

namespace kb = kfd::bench;

namespace {

// kfd's default pipeline (distance, view keyframe, denoise) with the view selector's thresholds
// out of reach: every dropped-set scan is dropped by the keyframe decision.
// `temporal_scans`: the evidence denoiser's (issue 25; 0 = the default's).
kfd::Pipeline::Params viewDropParams(std::size_t temporal_scans = 0) {
    kfd::Pipeline::Params p;
    p.get<kfd::DistanceStage>() = kb::paperParams().get<kfd::DistanceStage>();
    p.get<kfd::ViewKeyframeStage>() = kb::viewParamsThatDrop();
    p.get<kfd::EvidenceDenoiseStage>().temporal_scans = temporal_scans;
    return p;
}

// kfd's default pipeline since issue 35 (odometry check, distance, track, view keyframe,
// evidence denoise) with the view selector's thresholds out of reach, as viewDropParams.
kfd::Pipeline::Params trackDropParams() {
    kfd::Pipeline::Params p = viewDropParams();
    p.stages = kfd::kfdDefaults().stages;
    return p;
}

// The evidence denoiser on the keyframes alone (temporal_scans 0: before issue 25).
kfd::Pipeline::Params keyframesOnlyParams() {
    kfd::Pipeline::Params p = kb::paperParams(kfd::DenoiseVariant::Evidence);
    p.get<kfd::EvidenceDenoiseStage>().temporal_scans = 0;
    return p;
}

// The evidence denoiser with the raw scan just before each keyframe (issue 25).
kfd::Pipeline::Params temporalParams() {
    kfd::Pipeline::Params p = kb::paperParams(kfd::DenoiseVariant::Evidence);
    p.get<kfd::EvidenceDenoiseStage>().temporal_scans = 1;
    return p;
}

// The same placed by the track stage's poses (track_alignment, off by default: issue 39).
kfd::Pipeline::Params trackedParams() {
    kfd::Pipeline::Params p = temporalParams();
    p.get<kfd::EvidenceDenoiseStage>().track_alignment = true;
    return p;
}

// The same with only the raw scan just before placed by them (track_raw_alignment, on by
// default since issue 39's sixth step; the temporal case above has no track stage).
kfd::Pipeline::Params rawTrackedParams() {
    kfd::Pipeline::Params p = temporalParams();
    p.get<kfd::EvidenceDenoiseStage>().track_raw_alignment = true;
    return p;
}

// The same with the keyframe's own alignment started from their poses (track_keyframe_start,
// off by default; on by itself where the scans carry no odometry).
kfd::Pipeline::Params keyframeStartParams() {
    kfd::Pipeline::Params p = rawTrackedParams();
    p.get<kfd::EvidenceDenoiseStage>().track_keyframe_start = true;
    return p;
}

// The same with the scan just after each keyframe too (next_scan, issue 25).
kfd::Pipeline::Params nextScanParams() {
    kfd::Pipeline::Params p = temporalParams();
    p.get<kfd::EvidenceDenoiseStage>().next_scan = true;
    return p;
}

struct Context {
    kb::Scenario sc = kb::makeScenario();
    std::vector<kfd::Scan> work = sc.keyframes;            // scratch copies of the keyframe set
    std::vector<kfd::Scan> work_dropped = sc.dropped;      // ... and of the dropped set
    std::vector<kfd::Scan> work_loop = sc.loop_keyframes;  // ... and of the loop keyframes
    std::vector<std::vector<double>> hist;                 // histograms of the keyframe set
    std::vector<double> out;
    kfd::Histogram histogram{kfd::Histogram::Params{20}};
    kfd::DistanceFilter distance{kb::paperParams().get<kfd::DistanceStage>()};
    kfd::KeyframeSelector selector{kb::paperParams().get<kfd::KeyframeStage>()};
    kfd::ViewKeyframeSelector view{kb::viewParamsThatDrop()};
    kfd::ViewKeyframeSelector view_lo{kb::viewParamsThatDrop()};
    std::vector<kfd::Scan> dropped_lo;  // the dropped set without odometry
    kb::StageFilter<kfd::DenoiseStage> reference{
        kb::paperParams(kfd::DenoiseVariant::Reference).get<kfd::DenoiseStage>()};
    kb::StageFilter<kfd::RangeAwareDenoiseStage> range_aware{
        kb::paperParams(kfd::DenoiseVariant::RangeAware).get<kfd::RangeAwareDenoiseStage>()};
    kb::StageFilter<kfd::EvidenceDenoiseStage> evidence{
        keyframesOnlyParams().get<kfd::EvidenceDenoiseStage>()};
    kb::StageFilter<kfd::EvidenceDenoiseStage> evidence_temporal{
        temporalParams().get<kfd::EvidenceDenoiseStage>()};
    // The same behind a track stage that placed every scan (issue 39: no alignment of its own).
    kb::StageFilter<kfd::EvidenceDenoiseStage> evidence_tracked{
        trackedParams().get<kfd::EvidenceDenoiseStage>()};
    kb::StageFilter<kfd::EvidenceDenoiseStage> evidence_raw_tracked{
        rawTrackedParams().get<kfd::EvidenceDenoiseStage>()};
    kb::StageFilter<kfd::EvidenceDenoiseStage> evidence_keyframe_start{
        keyframeStartParams().get<kfd::EvidenceDenoiseStage>()};
    kb::StageFilter<kfd::EvidenceDenoiseStage> evidence_next{
        nextScanParams().get<kfd::EvidenceDenoiseStage>()};
    kfd::DbscanFilter dbscan{kfd::DbscanFilter::Params{0.7, 10}};
    kfd::RadiusOutlierFilter radius{kfd::RadiusOutlierFilter::Params{}};
    kfd::StatisticalOutlierFilter sor{kfd::StatisticalOutlierFilter::Params{}};
    // laser_filters' definitions (issue 39): speckle 80 m / 0.1 m / window 2, shadows 10-170 deg,
    // window 1, neighbours 0, the start point removed.
    kfd::SpeckleFilter speckle{kfd::SpeckleFilter::Params{false, 80.0, 0.1, 2}};
    kfd::ShadowFilter shadow{kfd::ShadowFilter::Params{10.0, 170.0, 1, 0, true}};
    kfd::Pipeline pipe_dropped{kb::paperParams()};
    kfd::Pipeline pipe_reference{kb::paperParams(kfd::DenoiseVariant::Reference)};
    kfd::Pipeline pipe_range_aware{kb::paperParams(kfd::DenoiseVariant::RangeAware)};
    kfd::Pipeline pipe_view{viewDropParams()};            // kfd's default pipeline, dropping
    kfd::Pipeline pipe_view_temporal{viewDropParams(1)};  // the same, keeping the dropped scan
    kfd::StreamFilter door{viewDropParams()};     // the same behind the one door (MRPT scans)
    kfd::Pipeline pipe_track{trackDropParams()};  // kfd's default pipeline since issue 35
    kfd::ScanTracker tracker;                     // the track stage's algorithm alone
    std::vector<mrpt::obs::CObservation2DRangeScan> obs_dropped, obs_work;
    std::size_t sink = 0;       // results feed this so nothing is optimised away
    std::size_t surprises = 0;  // dropped-set scans kept or keyframe-set scans dropped

    Context() {
        evidence_tracked.trackAtOdometry(0.01f);
        evidence_raw_tracked.trackAtOdometry(0.01f);
        evidence_keyframe_start.trackAtOdometry(0.01f);
        hist.resize(sc.keyframes.size());
        for (std::size_t k = 0; k < hist.size(); ++k) histogram.compute(sc.keyframes[k], hist[k]);
        for (const auto& s : sc.prefix) selector.filter(s);
        for (const auto& s : sc.dropped) dropped_lo.push_back(kb::laserOnly(s));
        view.filter(sc.prefix.back());
        view_lo.filter(kb::laserOnly(sc.prefix.back()));
        for (kfd::Scan s : sc.prefix) pipe_dropped.process(s);
        kfd::Scan first = sc.prefix.back();
        pipe_view.process(first);  // the keyframe every dropped-set scan is measured against
        kfd::Scan first_t = sc.prefix.back();
        pipe_view_temporal.process(first_t);
        auto first_obs = kb::toMrpt(sc.prefix.back());
        door.process(first_obs, sc.prefix.back().odometry);
        for (const auto& s : sc.dropped) obs_dropped.push_back(kb::toMrpt(s));
        obs_work = obs_dropped;
        kfd::Scan first_track = sc.prefix.back();
        pipe_track.process(first_track);
        tracker.track(sc.prefix.back());
        tracker.accept();
    }
};

}  // namespace

// The counted calls: one scan each. pipeline_dropped_view is kfd's default pipeline on a
// dropped scan (issue 20's target); door_dropped_view the same through StreamFilter::process
// with an MRPT scan (the check and the MRPT adapter included).
extern "C" {
__attribute__((noinline)) void kfd_ir_histogram(Context& c, std::size_t k) {
    c.sink += c.histogram.compute(c.sc.keyframes[k], c.out);
}
__attribute__((noinline)) void kfd_ir_pearson(Context& c, std::size_t k) {
    const auto& a = c.hist[k];
    const auto& b = c.hist[(k + 1) % c.hist.size()];
    c.sink += kfd::pearson(a.data(), b.data(), a.size()) > 0.5;
}
__attribute__((noinline)) void kfd_ir_distance_filter(Context& c, std::size_t k) {
    c.sink += c.distance.filter(c.work[k]).valid_out;
}
__attribute__((noinline)) void kfd_ir_keyframe_decision(Context& c, std::size_t k) {
    c.surprises += c.selector.filter(c.sc.dropped[k]).keyframe;
}
__attribute__((noinline)) void kfd_ir_keyframe_view(Context& c, std::size_t k) {
    c.surprises += c.view.filter(c.sc.dropped[k]).keyframe;
}
__attribute__((noinline)) void kfd_ir_keyframe_view_laser_only(Context& c, std::size_t k) {
    c.surprises += c.view_lo.filter(c.dropped_lo[k]).keyframe;
}
__attribute__((noinline)) void kfd_ir_denoise_reference(Context& c, std::size_t k) {
    c.sink += c.reference.filter(c.work[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_denoise_range_aware(Context& c, std::size_t k) {
    c.sink += c.range_aware.filter(c.work[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_denoise_evidence(Context& c, std::size_t k) {
    c.sink += c.evidence.filter(c.work_loop[k]).points_removed;
}
// A loop keyframe after the scan just before it was dropped: the observe (the dropped scan's
// share, counted apart) and the keyframe's filter with that raw scan as evidence.
__attribute__((noinline)) void kfd_ir_evidence_observe(Context& c, std::size_t k) {
    c.evidence_temporal.observe(c.sc.loop_before[k]);
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_temporal_keyframe(Context& c,
                                                                         std::size_t k) {
    c.sink += c.evidence_temporal.filter(c.work_loop[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_temporal(Context& c, std::size_t k) {
    kfd_ir_evidence_observe(c, k);
    kfd_ir_denoise_evidence_temporal_keyframe(c, k);
}
// The same with the track stage's poses (issue 39, track_alignment).
__attribute__((noinline)) void kfd_ir_evidence_observe_tracked(Context& c, std::size_t k) {
    c.evidence_tracked.observe(c.sc.loop_before[k]);
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_tracked_keyframe(Context& c, std::size_t k) {
    c.sink += c.evidence_tracked.filter(c.work_loop[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_tracked(Context& c, std::size_t k) {
    kfd_ir_evidence_observe_tracked(c, k);
    kfd_ir_denoise_evidence_tracked_keyframe(c, k);
}
// The same with only the raw scan placed by the track stage's poses (track_raw_alignment).
__attribute__((noinline)) void kfd_ir_evidence_observe_raw_tracked(Context& c, std::size_t k) {
    c.evidence_raw_tracked.observe(c.sc.loop_before[k]);
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_raw_tracked_keyframe(Context& c,
                                                                            std::size_t k) {
    c.sink += c.evidence_raw_tracked.filter(c.work_loop[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_raw_tracked(Context& c, std::size_t k) {
    kfd_ir_evidence_observe_raw_tracked(c, k);
    kfd_ir_denoise_evidence_raw_tracked_keyframe(c, k);
}
// The same with the keyframe's alignment started from the tracker's step (track_keyframe_start).
__attribute__((noinline)) void kfd_ir_evidence_observe_keyframe_start(Context& c, std::size_t k) {
    c.evidence_keyframe_start.observe(c.sc.loop_before[k]);
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_keyframe_start_keyframe(Context& c,
                                                                               std::size_t k) {
    c.sink += c.evidence_keyframe_start.filter(c.work_loop[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_keyframe_start(Context& c, std::size_t k) {
    kfd_ir_evidence_observe_keyframe_start(c, k);
    kfd_ir_denoise_evidence_keyframe_start_keyframe(c, k);
}
// The same keyframe confirmed against the scan just after it too (next_scan): the observe
// of the scan before and the keyframe's filter with both raw scans.
__attribute__((noinline)) void kfd_ir_denoise_evidence_next_keyframe(Context& c, std::size_t k) {
    c.sink += c.evidence_next.filter(c.work_loop[k], &c.sc.loop_after[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_denoise_evidence_next(Context& c, std::size_t k) {
    c.evidence_next.observe(c.sc.loop_before[k]);
    kfd_ir_denoise_evidence_next_keyframe(c, k);
}
__attribute__((noinline)) void kfd_ir_speckle_loop(Context& c, std::size_t k) {
    c.sink += c.speckle.filter(c.work_loop[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_shadow_loop(Context& c, std::size_t k) {
    c.sink += c.shadow.filter(c.work_loop[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_dbscan_loop(Context& c, std::size_t k) {
    c.sink += c.dbscan.filter(c.work_loop[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_dbscan(Context& c, std::size_t k) {
    c.sink += c.dbscan.filter(c.work[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_radius_outlier(Context& c, std::size_t k) {
    c.sink += c.radius.filter(c.work[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_statistical_outlier(Context& c, std::size_t k) {
    c.sink += c.sor.filter(c.work[k]).points_removed;
}
__attribute__((noinline)) void kfd_ir_pipeline_dropped(Context& c, std::size_t k) {
    c.surprises += c.pipe_dropped.process(c.work_dropped[k]).keep;
}
__attribute__((noinline)) void kfd_ir_pipeline_dropped_view(Context& c, std::size_t k) {
    c.surprises += c.pipe_view.process(c.work_dropped[k]).keep;
}
__attribute__((noinline)) void kfd_ir_pipeline_dropped_view_temporal(Context& c, std::size_t k) {
    c.surprises += c.pipe_view_temporal.process(c.work_dropped[k]).keep;
}
__attribute__((noinline)) void kfd_ir_door_dropped_view(Context& c, std::size_t k) {
    c.surprises += c.door.process(c.obs_work[k], c.sc.dropped[k].odometry).keep;
}
__attribute__((noinline)) void kfd_ir_pipeline_dropped_track(Context& c, std::size_t k) {
    c.surprises += c.pipe_track.process(c.work_dropped[k]).keep;
}
__attribute__((noinline)) void kfd_ir_tracker(Context& c, std::size_t k) {
    c.sink += c.tracker.track(c.sc.dropped[k]).pairs;
}
__attribute__((noinline)) void kfd_ir_pipeline_keyframe_reference(Context& c, std::size_t k) {
    c.surprises += !c.pipe_reference.process(c.work[k]).keep;
}
__attribute__((noinline)) void kfd_ir_pipeline_keyframe_range_aware(Context& c, std::size_t k) {
    c.surprises += !c.pipe_range_aware.process(c.work[k]).keep;
}
}

namespace {

struct Case {
    const char* name;
    void (*call)(Context&, std::size_t);
    bool dropped_set;       // runs on the dropped set (else on the keyframe set)
    bool loop_set = false;  // runs on the loop keyframes (overrides dropped_set)
};

const Case kCases[] = {
    {"histogram", kfd_ir_histogram, false},
    {"pearson", kfd_ir_pearson, false},
    {"distance_filter", kfd_ir_distance_filter, false},
    {"keyframe_decision", kfd_ir_keyframe_decision, true},
    {"keyframe_view", kfd_ir_keyframe_view, true},
    {"keyframe_view_laser_only", kfd_ir_keyframe_view_laser_only, true},
    {"denoise_reference", kfd_ir_denoise_reference, false},
    {"denoise_range_aware", kfd_ir_denoise_range_aware, false},
    {"denoise_evidence", kfd_ir_denoise_evidence, false, true},
    {"denoise_evidence_temporal", kfd_ir_denoise_evidence_temporal, false, true},
    {"denoise_evidence_tracked", kfd_ir_denoise_evidence_tracked, false, true},
    {"denoise_evidence_raw_tracked", kfd_ir_denoise_evidence_raw_tracked, false, true},
    {"denoise_evidence_keyframe_start", kfd_ir_denoise_evidence_keyframe_start, false, true},
    {"denoise_evidence_next", kfd_ir_denoise_evidence_next, false, true},
    {"speckle_loop", kfd_ir_speckle_loop, false, true},
    {"shadow_loop", kfd_ir_shadow_loop, false, true},
    {"dbscan_loop", kfd_ir_dbscan_loop, false, true},
    {"dbscan", kfd_ir_dbscan, false},
    {"radius_outlier", kfd_ir_radius_outlier, false},
    {"statistical_outlier", kfd_ir_statistical_outlier, false},
    {"pipeline_dropped", kfd_ir_pipeline_dropped, true},
    {"pipeline_dropped_view", kfd_ir_pipeline_dropped_view, true},
    {"pipeline_dropped_view_temporal", kfd_ir_pipeline_dropped_view_temporal, true},
    {"door_dropped_view", kfd_ir_door_dropped_view, true},
    {"pipeline_dropped_track", kfd_ir_pipeline_dropped_track, true},
    {"tracker", kfd_ir_tracker, true},
    {"pipeline_keyframe_reference", kfd_ir_pipeline_keyframe_reference, false},
    {"pipeline_keyframe_range_aware", kfd_ir_pipeline_keyframe_range_aware, false},
};

// Untimed cycle: the same work as a counted call, without going through kfd_ir_*.
void warmUp(Context& c, const Case& cs) {
    const std::string name = cs.name;
    if (cs.loop_set) {
        for (std::size_t k = 0; k < c.sc.loop_keyframes.size(); ++k) {
            kb::restoreValid(c.sc.loop_keyframes[k], c.work_loop[k]);
            if (name == "denoise_evidence") c.evidence.filter(c.work_loop[k]);
            if (name == "denoise_evidence_temporal") {
                c.evidence_temporal.observe(c.sc.loop_before[k]);
                c.evidence_temporal.filter(c.work_loop[k]);
            }
            if (name == "denoise_evidence_tracked") {
                c.evidence_tracked.observe(c.sc.loop_before[k]);
                c.evidence_tracked.filter(c.work_loop[k]);
            }
            if (name == "denoise_evidence_raw_tracked") {
                c.evidence_raw_tracked.observe(c.sc.loop_before[k]);
                c.evidence_raw_tracked.filter(c.work_loop[k]);
            }
            if (name == "denoise_evidence_keyframe_start") {
                c.evidence_keyframe_start.observe(c.sc.loop_before[k]);
                c.evidence_keyframe_start.filter(c.work_loop[k]);
            }
            if (name == "denoise_evidence_next") {
                c.evidence_next.observe(c.sc.loop_before[k]);
                c.evidence_next.filter(c.work_loop[k], &c.sc.loop_after[k]);
            }
            if (name == "speckle_loop") c.speckle.filter(c.work_loop[k]);
            if (name == "shadow_loop") c.shadow.filter(c.work_loop[k]);
            if (name == "dbscan_loop") c.dbscan.filter(c.work_loop[k]);
        }
        return;
    }
    const std::size_t n = cs.dropped_set ? c.sc.dropped.size() : c.sc.keyframes.size();
    for (std::size_t k = 0; k < n; ++k) {
        kfd::Scan& s = cs.dropped_set ? c.work_dropped[k] : c.work[k];
        kb::restoreValid(cs.dropped_set ? c.sc.dropped[k] : c.sc.keyframes[k], s);
        if (name == "histogram") c.histogram.compute(c.sc.keyframes[k], c.out);
        if (name == "distance_filter") c.distance.filter(s);
        if (name == "keyframe_decision") c.selector.filter(c.sc.dropped[k]);
        if (name == "keyframe_view") c.view.filter(c.sc.dropped[k]);
        if (name == "keyframe_view_laser_only") c.view_lo.filter(c.dropped_lo[k]);
        if (name == "denoise_reference") c.reference.filter(s);
        if (name == "denoise_range_aware") c.range_aware.filter(s);
        if (name == "dbscan") c.dbscan.filter(s);
        if (name == "radius_outlier") c.radius.filter(s);
        if (name == "statistical_outlier") c.sor.filter(s);
        if (name == "pipeline_dropped") c.pipe_dropped.process(s);
        if (name == "pipeline_dropped_view") c.pipe_view.process(s);
        if (name == "pipeline_dropped_view_temporal") c.pipe_view_temporal.process(s);
        if (name == "door_dropped_view") {
            c.obs_work[k] = c.obs_dropped[k];
            c.door.process(c.obs_work[k], c.sc.dropped[k].odometry);
        }
        if (name == "pipeline_dropped_track") c.pipe_track.process(s);
        if (name == "tracker") c.tracker.track(c.sc.dropped[k]);
        if (name == "pipeline_keyframe_reference") c.pipe_reference.process(s);
        if (name == "pipeline_keyframe_range_aware") c.pipe_range_aware.process(s);
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc >= 2 && (!std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "--help"))) {
        std::printf("usage: kfd_bench_instructions [N [CASE...]]\ncases:");
        for (const auto& cs : kCases) std::printf(" %s", cs.name);
        std::printf("\n");
        return 0;
    }
    const long n = argc >= 2 ? std::atol(argv[1]) : 160;
    if (n <= 0) {
        std::fprintf(stderr, "kfd_bench_instructions: N must be > 0\n");
        return 2;
    }
    std::vector<const Case*> run;
    for (int a = 2; a < argc; ++a) {
        const Case* found = nullptr;
        for (const auto& cs : kCases)
            if (!std::strcmp(cs.name, argv[a])) found = &cs;
        if (!found) {
            std::fprintf(stderr, "kfd_bench_instructions: unknown case '%s'\n", argv[a]);
            return 2;
        }
        run.push_back(found);
    }
    if (run.empty())
        for (const auto& cs : kCases) run.push_back(&cs);

    Context c;
    for (const Case* cs : run) {
        warmUp(c, *cs);
        const std::size_t size = cs->loop_set      ? c.sc.loop_keyframes.size()
                                 : cs->dropped_set ? c.sc.dropped.size()
                                                   : c.sc.keyframes.size();
        for (long i = 0; i < n; ++i) {
            const std::size_t k = static_cast<std::size_t>(i) % size;
            if (cs->loop_set)
                kb::restoreValid(c.sc.loop_keyframes[k], c.work_loop[k]);
            else if (cs->dropped_set) {
                kb::restoreValid(c.sc.dropped[k], c.work_dropped[k]);
                c.obs_work[k] = c.obs_dropped[k];  // assigned in place: no allocation
            } else
                kb::restoreValid(c.sc.keyframes[k], c.work[k]);
            cs->call(c, k);
        }
        std::printf("case %s calls %ld\n", cs->name, n);
    }
    if (c.surprises) {
        std::fprintf(stderr, "kfd_bench_instructions: %zu scans took the wrong path\n",
                     c.surprises);
        return 1;
    }
    std::printf("checksum %zu\n", c.sink);
    return 0;
}
