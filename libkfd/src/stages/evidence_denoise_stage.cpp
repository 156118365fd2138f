#include "kfd/stages/evidence_denoise_stage.h"

#include "kfd/algorithms/scan_tracker.h"
#include "kfd/pipeline/stage_keys.h"

#include <utility>
#include <vector>

namespace kfd {

namespace {
using P = EvidenceDenoiseStage::Params;

// Steps 1-5: segments, the temporal evidence and the bound.
std::vector<StageKey> methodKeys() {
    return {
        keys::real<P>("min_object_size_m", "min_object_size_m",
                      "width of the smallest object kept without support (m)", 0, 100, false,
                      [](P& p) -> double& { return p.min_object_size_m; }),
        keys::real<P>("incidence_deg", "incidence_deg", "breakpoint incidence limit lambda (deg)",
                      0, 89.9, true, [](P& p) -> double& { return p.incidence_deg; }),
        keys::real<P>("sigma_m", "sigma_m", "sensor range noise (m), 0 = estimated from the scans",
                      0, 10, false, [](P& p) -> double& { return p.sigma_m; }),
        keys::count<P>("max_gap_beams", "max_gap_beams", "missing beams a surface may span", 0, 16,
                       [](P& p) -> std::size_t& { return p.max_gap_beams; }),
        keys::count<P>("max_small_points", "max_small_points",
                       "segments of at most this many points may be small", 0, 1000,
                       [](P& p) -> std::size_t& { return p.max_small_points; }),
        keys::boolean<P>("dropout_fragments", "dropout_fragments",
                         "a segment of 2+ returns between dropouts (no other return within "
                         "max_gap_beams + 1 beams) is a surface, never small",
                         [](P& p) -> bool& { return p.dropout_fragments; }),
        keys::boolean<P>("temporal", "temporal",
                         "compare with the previous keyframe (needs odometry)",
                         [](P& p) -> bool& { return p.temporal; }),
        keys::real<P>("pose_trans_error_m", "pose_trans_error_m",
                      "odometry translation error of one keyframe step (m)", 0, 10, false,
                      [](P& p) -> double& { return p.pose_trans_error_m; }),
        keys::real<P>("pose_rot_error_deg", "pose_rot_error_deg",
                      "odometry rotation error of one keyframe step (deg)", 0, 90, false,
                      [](P& p) -> double& { return p.pose_rot_error_deg; }),
        keys::real<P>("motion_error_fraction", "motion_error_fraction",
                      "odometry error per metre and per radian of the step", 0, 10, false,
                      [](P& p) -> double& { return p.motion_error_fraction; }),
        keys::real<P>("max_removed_fraction", "max_removed_fraction",
                      "largest share of a scan's valid returns removed (step 5)", 0, 1, true,
                      [](P& p) -> double& { return p.max_removed_fraction; }),
        keys::real<P>("max_confirmed_fraction", "max_confirmed_fraction",
                      "removal beyond the bound kept up to this share when the raw "
                      "scan just before confirms it (step 5; 0 = off)",
                      0, 1, false, [](P& p) -> double& { return p.max_confirmed_fraction; }),
        keys::real<P>("confirm_support", "confirm_support",
                      "... when it supports this share of the other returns it judged", 0, 1, true,
                      [](P& p) -> double& { return p.confirm_support; })};
}

// Which evidence besides the keyframes, and the steps after the bound (4b, 6, 7).
std::vector<StageKey> optionKeys() {
    return {
        keys::count<P>("temporal_scans", "temporal_scans",
                       "raw scans kept before a keyframe (the dropped ones) as "
                       "temporal evidence with margins from their alignment; 0 = keyframes only",
                       0, 16, [](P& p) -> std::size_t& { return p.temporal_scans; }),
        keys::boolean<P>("next_scan", "next_scan",
                         "also confirm a keyframe against the scan just after it (one "
                         "scan of latency: the keyframe is output when the next scan arrives)",
                         [](P& p) -> bool& { return p.next_scan; }),
        keys::boolean<P>("veil", "veil",
                         "remove mixed pixels between a near and a far surface (step 6)",
                         [](P& p) -> bool& { return p.veil; }),
        keys::boolean<P>("track_alignment", "track_alignment",
                         "where the track stage placed a keyframe and a reference, align them "
                         "by its poses instead of the denoiser's own alignment",
                         [](P& p) -> bool& { return p.track_alignment; }),
        keys::boolean<P>("track_raw_alignment", "track_raw_alignment",
                         "the same for the raw scans kept before a keyframe only "
                         "(temporal_scans); the keyframe before it still aligned by the denoiser",
                         [](P& p) -> bool& { return p.track_raw_alignment; }),
        keys::boolean<P>("track_keyframe_start", "track_keyframe_start",
                         "where the track stage placed a keyframe and the one before, start the "
                         "denoiser's own alignment between them from its poses, not odometry "
                         "(without odometry: always)",
                         [](P& p) -> bool& { return p.track_keyframe_start; }),
        keys::count<P>("tracked_refine_iterations", "tracked_refine_iterations",
                       "... and run only the last this many of its 3 Gauss-Newton steps", 0, 3,
                       [](P& p) -> std::size_t& { return p.tracked_refine_iterations; }),
        keys::count<P>("tracked_refine_samples", "tracked_refine_samples",
                       "... with this many of a keyframe's returns per step (of 128)", 1, 128,
                       [](P& p) -> std::size_t& { return p.tracked_refine_samples; }),
        keys::boolean<P>("spikes", "spikes",
                         "remove a return beyond both neighbours' ranges that the temporal "
                         "evidence does not support",
                         [](P& p) -> bool& { return p.spikes; }),
        keys::boolean<P>("spike_object_support", "spike_object_support",
                         "... and count a reference's support for a spike only where that "
                         "reference saw an object there, not a smooth surface",
                         [](P& p) -> bool& { return p.spike_object_support; }),
        keys::boolean<P>("keep_surfaces", "keep_surfaces",
                         "never remove a run of returns on a line at the scan's noise (step 7)",
                         [](P& p) -> bool& { return p.keep_surfaces; }),
        keys::count<P>("surface_min_beams", "surface_min_beams",
                       "returns a run on a line needs to be kept as a surface (step 7)", 2, 1000,
                       [](P& p) -> std::size_t& { return p.surface_min_beams; }),
        keys::real<P>("surface_sigmas", "surface_sigmas",
                      "RMS distance to the line a surface may have, in range noise sigmas "
                      "(step 7)",
                      0, 100, false, [](P& p) -> double& { return p.surface_sigmas; })};
}
}  // namespace

std::vector<StageKey> EvidenceDenoiseStage::keys() {
    std::vector<StageKey> all = methodKeys();
    for (StageKey& k : optionKeys()) all.push_back(std::move(k));
    return all;
}

namespace {
// Where the track stage (earlier in the chain) placed the scan, when it tracked it.
const EvidenceFilter::Tracked* trackedBy(const ScanReport& chain, EvidenceFilter::Tracked& t) {
    const TrackResult* r = chain.find<TrackResult>();
    if (r == nullptr || !r->tracked()) return nullptr;
    t.pose = r->pose;
    t.rms_m = r->rms_m;
    return &t;
}
}  // namespace

void EvidenceDenoiseStage::observeDropped(const Scan& scan, const ScanReport& chain) {
    EvidenceFilter::Tracked t;
    filter_.observe(scan, trackedBy(chain, t));
}

bool EvidenceDenoiseStage::finish(Scan& scan, StageReport& report, const ScanReport& chain,
                                  const Scan* next) {
    DenoiseResult res = startDenoising(scan, DenoiseVariant::Evidence);
    // Marks its segments' noise flags and removes their points itself.
    EvidenceFilter::Tracked t;
    const auto r = filter_.filter(scan, clusters_, next, trackedBy(chain, t));
    res.points_removed += r.points_removed;
    res.temporal = r.temporal;
    res.sigma = r.sigma;
    res.sigma_measured = r.sigma_measured;
    res.free_points = r.free_points;
    res.stale_references = r.stale_references;
    res.capped = r.capped;
    res.confirmed = r.confirmed;
    res.recent = r.recent;
    res.next = r.next;
    res.spikes = r.spikes;
    res.veils = r.veils;
    res.surface_kept = r.surface_kept;
    return endDenoising(clusters_, res, report);
}

namespace {
// How the bound on removal acted (EvidenceFilter step 5): "none", "stale_references" (temporal
// evidence ignored), "capped" (cut to the bound) or "confirmed" (above it, confirmed by the scan
// just before and removed whole).
const char* boundOf(const DenoiseResult& r) {
    return r.capped             ? "capped"
           : r.stale_references ? "stale_references"
           : r.confirmed        ? "confirmed"
                                : "none";
}
}  // namespace

std::vector<StageColumn> EvidenceDenoiseStage::columns() {
    std::vector<StageColumn> c = denoiseColumns();
    c.push_back(diagnosticColumn<DenoiseResult>(
        "denoise_bound",
        "how the bound on removal acted: none, stale_references, capped or confirmed", "%s",
        boundOf));
    c.push_back(diagnosticColumn<DenoiseResult>(
        "sigma_mm", "the range noise the evidence used (mm; measured, then floored)", "%.2f",
        [](const DenoiseResult& r) { return 1e3 * r.sigma; }));
    c.push_back(diagnosticColumn<DenoiseResult>("spikes", "spikes removed (step 4b)", "%zu",
                                                [](const DenoiseResult& r) { return r.spikes; }));
    c.push_back(diagnosticColumn<DenoiseResult>("veils", "mixed pixels removed (step 6)", "%zu",
                                                [](const DenoiseResult& r) { return r.veils; }));
    c.push_back(diagnosticColumn<DenoiseResult>(
        "surface_kept", "returns kept because they form a surface (step 7)", "%zu",
        [](const DenoiseResult& r) { return r.surface_kept; }));
    return c;
}

std::vector<StageCounter> EvidenceDenoiseStage::counters() {
    using R = DenoiseResult;
    return {diagnosticCounter<R>(
                "scans_denoise_stale", "kept scans whose references were stale (spatial only)",
                true, [](const R& r) { return std::string(boundOf(r)) == "stale_references"; }),
            diagnosticCounter<R>("scans_denoise_capped",
                                 "kept scans whose removal was cut to the bound", true,
                                 [](const R& r) { return r.capped; }),
            diagnosticCounter<R>(
                "scans_denoise_confirmed",
                "kept scans above the bound, confirmed by the scan just before (all removed)", true,
                [](const R& r) { return std::string(boundOf(r)) == "confirmed"; })};
}

}  // namespace kfd
