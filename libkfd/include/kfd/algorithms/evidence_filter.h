// kfd's evidence variant of the denoiser (beyond the paper): spatial and temporal evidence,
// with thresholds derived from the scan itself. std only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "kfd/paper/clusters.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

template <class T>
struct PointToLineSystem;  // kfd/algorithms/point_to_line.h

/// Why: on real scans with injected noise, clustering by size alone finds few outliers and
/// removes real points (docs/CHANGELOG.md). A one-beam spike 0.2 m in front of a wall, a burst of
/// 20 beams at 1 m and a chair leg look alike to a clusterer; what differs is the evidence:
///  - spatial: does a return continue a surface of its neighbours?
///  - temporal: did the last keyframes see the same place, or see *through* it?
///
/// Per scan (n beams, O(n), no allocation once the buffers have grown):
///  1. Range noise sigma from the scan: a line in polar coordinates satisfies
///     1/r(i-1) + 1/r(i+1) = 2 cos(res) / r(i), so the residual e(i) of each beam against its
///     two neighbours is ~ N(0, 1.5 sigma^2) on any flat surface, at any incidence. sigma is
///     the lower decile of |e| (every fourth beam) scaled to a standard deviation, floored at
///     min_sigma_m and smoothed over scans, or fixed by sigma_m. Resolution comes from the
///     geometry: nothing is tuned per sensor.
///  2. Segments: consecutive returns (at most max_gap_beams missing between them) are one
///     surface when their distance is within the adaptive breakpoint
///     D = r_min sin(dtheta) / sin(lambda - dtheta) + 3 sqrt(2) sigma (Borges & Aldon 2004), or
///     when both lie on a line with their own neighbours (|e| <= 3 sqrt(1.5) sigma at both):
///     the second test keeps far walls seen at grazing angles in one piece, which the
///     breakpoint (and laser_filters' shadow filter) cut into single points.
///  3. Temporal evidence from the last two keyframes this filter saw. The step from the newest
///     comes from odometry, refined by a projective point-to-line alignment (refine_iterations
///     x refine_samples returns); where the scans carry no odometry it starts from the step of
///     the track stage's poses when it placed both (its last tracked_refine_iterations x
///     tracked_refine_samples only; track_keyframe_start: also with odometry), else from zero
///     motion. Each return is moved into the keyframe's sensor frame and compared with the
///     beams bracketing it:
///     - free: both bracketing beams reached beyond it by more than m: the keyframe saw
///       through this place (an outlier, or a moving object: a free return within
///       moving_object_m of a return that was free in the keyframe is "tracked" and kept);
///     - supported: within m plus one beam's arc of a keyframe return, or within m of the
///       keyframe's surface segment between the bracketing returns; the older keyframe may
///       support what the newest could not, never overrule free space;
///     - unknown otherwise (occluded before, out of the keyframe's view, no return there).
///     m = 3 sqrt(2) sigma + pose_trans_error_m + motion_error_fraction x translation
///         + range x (pose_rot_error_deg + motion_error_fraction x rotation),
///     plus range x resolution for the free test across a depth edge of the keyframe.
///     Returns off a line, of short segments, and every fourth along a line are classified.
///  3b. Temporal evidence from the raw scans just before (issue 25, temporal_scans > 0): the
///     last temporal_scans scans the filter was shown (observe(): the scans the keyframe stage
///     dropped; filter(): the keyframes, before removal) are kept as copies of their ranges,
///     flags and odometry. At a keyframe the newest is converted (points, breakpoint links)
///     and aligned like a keyframe (refineStep from odometry or zero motion); its step is
///     milliseconds long, so its margin comes from the alignment instead of the constants:
///     m = 3 max(sqrt(2) sigma, s) + motion_error_fraction x translation
///         + range x motion_error_fraction x rotation,
///     s = 1.4826 x the median |point-to-line residual| of the alignment's last iteration.
///     Where the track stage placed both scans (track_raw_alignment, on) their two tracked
///     poses place it instead and s is the larger of the two fits' RMS residuals.
///     Its verdict (free or supported) comes first; the keyframes decide what it left unknown
///     (and may still call a free return tracked); older raw scans only add support. Without
///     a usable alignment (too few pairs, no common odometry frame) it is not used.
///  3c. The raw scan just after (issue 25, next_scan = true, one scan of latency): the caller
///     holds the keyframe until the sensor's next scan (dropped or kept) and calls
///     filter(scan, out, &next) (kfd::Pipeline does this: Stage::defers). The next scan is
///     converted and aligned like step 3b's newest raw scan (same margins). The exact rule,
///     per classified return, from the raw scan before (B) and the one after (A):
///     - supported when B or A supports it;
///     - else free when B or A saw through it (then tracked when the newest keyframe says so);
///     - else unknown: the keyframes (and older raw scans) decide, as in step 3.
///     So a return seen by neither neighbour in space one of them saw through goes (a burst
///     that came and went); a surface newly revealed in the keyframe and still there in the
///     next scan stays. Without a next scan (the end of a log, a reset, a geometry change:
///     filter(scan, out) or next = nullptr) step 3b alone runs. The raw scans' verdict is
///     dropped together in step 5's first re-run (the keyframes alone).
///  4. Removal: every free return not on a line with its neighbours; every segment whose
///     classified returns are at least half free; every small segment without a supported
///     return. A segment is small when it has fewer points than an object of
///     min_object_size_m returns at its range, clamped to [1, max_small_points]: single beams
///     at 5 m on a 1-degree scanner, up to 3 at 1 m on a 0.25-degree one; with
///     dropout_fragments never a segment of 2+ returns between dropouts. Without temporal
///     evidence (first scan, too large a step, a new geometry) only small segments go.
///  5. Bounded removal (issue 22): when the removals of step 4 exceed max_removed_fraction of
///     the scan's valid returns, the references are stale (a turn or a walk away, odometry
///     that lied), not the scan: with step 3b's raw scans, steps 3-4 first run again on the
///     keyframes alone; then step 4 runs again without temporal evidence. When even that
///     exceeds the bound, the smallest segments go first until the bound is reached. Both are
///     reported (Result::stale_references, Result::capped).
///     Except for a burst (issue 25): when the raw scan just before was used and supports at
///     least confirm_support of the returns it judged outside the segments to be removed (its
///     alignment holds: the scan, not the reference, changed there), the removal stands up to
///     max_confirmed_fraction of the valid returns (Result::confirmed). A 3-20-beam burst is
///     up to 11 % of a 180-beam scan; stale references or a failed alignment leave free
///     returns scattered over the surfaces that stay, and fall back as above.
///  6. Mixed pixels (issue 39, veil = true): a beam that hit the edge of a near surface and
///     the far surface behind it returns a range between the two. A segment of at most
///     max_small_points returns whose neighbouring returns (within max_gap_beams) belong to
///     other segments, one nearer and one farther, and whose every return lies between them
///     by more than 3 sqrt(2) sigma, is such a veil; so are up to max_small_points returns at
///     the end of a segment next to a depth edge that leave its line (|e| > 3 sqrt(1.5) sigma
///     against the two returns inside them) toward the far side of the edge. Removed whatever
///     the temporal evidence says (a veil moves with the viewpoint: its references support it
///     by chance), none when they would take the scan's removal beyond the bound of step 5
///     (what steps 4, 4b and 5 left under it). Off by default (veil = false):
///     on the Freiburg logs it found 2 % more mixed pixels for 0.6 % of the real returns.
///  7. Surfaces kept (issue 39, keep_surfaces = true): a run of returns about to be removed
///     (consecutive beams, beams without a return do not break it) that a line fit calls a
///     surface is kept whatever steps 3-6 said: at least surface_min_beams returns within RMS
///     max(surface_sigmas x sigma, 2 cm, 0.5 % of their range) of a line (never stricter than
///     kfd-filter's summary flag, surface_m), neighbours at most four beam
///     spacings apart (algorithms/surface_run.h). A moving sensor's new viewpoint reveals
///     surfaces its references saw through; noise is not a line at the scan's noise level.
class EvidenceFilter {
  public:
    struct Params {
        double incidence_deg = 10.0;       // lambda (deg): breakpoint incidence limit (step 2)
        double sigma_m = 0.0;              // m: range noise; 0 = estimated from the scans (step 1)
        double min_sigma_m = 0.01;         // m: floor of the estimate (range quantisation)
        std::size_t max_gap_beams = 2;     // missing beams a segment may span (dropouts)
        double min_object_size_m = 0.1;    // m: the smallest real object kept without support
        std::size_t max_small_points = 3;  // points: a larger segment is never "small"
        /// Step 4: a segment of two or more returns with no other segment's return within
        /// max_gap_beams + 1 beams on either side is a surface seen between dropouts (a dark or
        /// grazed wall on a dense scanner), never small; a burst lies before a surface whose
        /// returns flank it. On: real returns kept +0.4 / +0.7 points on the two URG logs for
        /// -0.4 to -2.8 points of bursts there, the SICK logs unchanged, ICP-SLAM not
        /// significantly different (R = 20; docs/RESULTS.md, issue 39).
        bool dropout_fragments = true;
        bool temporal = true;  // use the previous keyframe (step 3)
        // Pose margins (step 3), wide enough for the steps between SLAM keyframes: with 2 cm,
        // 0.5 deg and 10 % the denoiser found more spikes but made ICP worse on two of four
        // logs (docs/CHANGELOG.md, "Do no harm").
        double pose_trans_error_m = 0.05;    // m: odometry error of one step
        double pose_rot_error_deg = 1.0;     // deg: the same, in rotation
        double motion_error_fraction = 0.2;  // error per metre / per radian of odometry step
        double moving_object_m = 0.5;        // m: reach of a moving object between keyframes
        double max_step_m = 2.0;             // m: farther keyframes give no temporal evidence
        double max_step_deg = 45.0;          // deg: the same, in rotation
        /// Issue 39: where the tracker placed both scans (Tracked), their step is the tracker's
        /// and the margin its RMS residual: no alignment of the denoiser's own. Off: it denoises
        /// better and costs 34 % fewer instructions, but ICP-SLAM after it is significantly
        /// worse on mit-csail (docs/RESULTS.md, issue 39).
        bool track_alignment = false;
        /// The same for the raw scans kept before a keyframe only (step 3b, temporal_scans; the
        /// newest one scan step away, where odometry glitches most; not the next scan of step
        /// 3c, which is not tracked yet), the keyframe before it still aligned by the denoiser
        /// (step 3). On: better recall and more real returns kept on every SICK log, 50 000
        /// fewer instructions per 1081-beam keyframe, ICP-SLAM after it not significantly
        /// different (docs/RESULTS.md, issue 39). Implied by track_alignment.
        bool track_raw_alignment = true;
        /// Step 3's keyframe alignment (track_alignment off), where the track stage placed this
        /// scan and the keyframe and the scans carry no odometry (a moving sensor, laser only:
        /// always), or with track_keyframe_start also where they do: it starts from the
        /// tracker's step instead of odometry's (or zero motion) and runs only the last
        /// tracked_refine_iterations steps of the schedule, with tracked_refine_samples returns
        /// (the gate already halved for the steps skipped). 198 000 instructions per 1081-beam
        /// keyframe instead of 241 000 and more real returns kept, but ICP-SLAM after it drifts
        /// on mit-csail in every run, as with track_alignment: off (docs/RESULTS.md, issue 39).
        bool track_keyframe_start = false;
        std::size_t tracked_refine_iterations = 1;  // <= refine_iterations
        std::size_t tracked_refine_samples = 32;    // <= refine_samples: returns per step then
        std::size_t refine_iterations = 3;          // Gauss-Newton steps aligning to the keyframe
        std::size_t refine_samples = 128;           // returns used per step (every n/128-th)
        double refine_gate_m = 1.0;  // m: pairing gate of the first step (halved after)
        /// Largest share of a scan's valid returns removed (step 5), in (0, 1]; 1 = no bound.
        /// 5 %: issue 22's bound; real bursts cover 0.3-1.2 % of a log's returns (CHANGELOG).
        double max_removed_fraction = 0.05;
        /// Step 5's exception for bursts: removals beyond max_removed_fraction are kept, up to
        /// max_confirmed_fraction of the valid returns, when the raw scan just before (step 3b)
        /// supports at least confirm_support of the returns it judged outside the removed
        /// segments (a good alignment: the burst is what changed, not the references).
        double max_confirmed_fraction = 0.25;
        double confirm_support = 0.9;
        /// Raw scans kept for step 3b (the scans just before a keyframe, dropped or not), in
        /// [0, 16]; 0 = keyframes only (no copies, the behaviour before issue 25). 1: on six
        /// real logs with injected noise (seed 7, kept scans) every kind's recall rose (isolated
        /// +1 to +8 points) at -0.04 to +0.16 points of real returns kept on the clean logs;
        /// 2 gave the same within 0.5 points (docs/CHANGELOG.md, issue 25).
        std::size_t temporal_scans = 1;
        /// Step 3c: also confirm a keyframe against the raw scan just after it. Costs one scan
        /// of latency (kfd::Pipeline holds the keyframe until the next scan; a node publishes
        /// it one scan later): for offline use and nodes that can afford it. Needs temporal.
        bool next_scan = false;
        /// Step 4b: remove a return nearer or farther than both its neighbours by more than
        /// 3 sqrt(2) sigma, off a line, that no reference supports (a spike off the surface its
        /// neighbours agree on); none when they would take the scan beyond the step 5 bound
        /// (clutter, or a scan the bound already cut). On: +0.2 to +0.9 points of isolated
        /// spikes found on six real logs (three seeds) for at most 0.08 points of real returns;
        /// ICP-SLAM not significantly different (R = 20; docs/RESULTS.md, issue 39).
        bool spikes = true;
        /// Step 4b: a reference keeps a spike only where it saw an object there too (one of its
        /// returns within the support margin that is itself off its neighbours' ranges by more
        /// than the pair margin, or beside a dropout); a reference that saw only a smooth
        /// surface there (each such return within the pair margin of both neighbours) supports
        /// the surface, not the spike. Off: any support keeps it (the third step's test). On:
        /// isolated spikes +0 to +2.4 points on six real logs (held-out seeds 3901, 5077), real
        /// returns kept -0.005 to -0.05 points (docs/RESULTS.md, issue 39).
        bool spike_object_support = true;
        /// Step 6: remove mixed pixels at depth edges.
        bool veil = false;  // off: on SICK logs it costs more real returns than it finds (issue 39)
        /// Step 7: never remove a run of returns on a line (surface_min_beams returns within
        /// RMS max(surface_sigmas x sigma, 2 cm, 0.5 % of their range) of a line).
        bool keep_surfaces = true;
        std::size_t surface_min_beams = 5;  // returns
        double surface_sigmas = 2.0;        // RMS tolerance in units of the range noise sigma
    };

    struct Result {
        std::size_t points_removed = 0;
        std::size_t segments = 0;
        std::size_t small_segments = 0;  // small segments removed
        std::size_t free_points = 0;     // returns in space the previous keyframe saw through
        std::size_t supported = 0;       // returns the previous keyframe confirmed
        std::size_t tracked = 0;         // free, but near a moving object seen before: kept
        bool temporal = false;           // temporal evidence was used for this scan
        bool refined = false;            // the odometry step was refined against the keyframe
        double sigma = 0.0;              // m: range noise used
        /// m: the scans' residuals' own estimate, before the floor min_sigma_m (smoothed over
        /// scans like sigma); 0 when nothing was measured (sigma_m set, or too few residuals
        /// so far). sigma is the floor when this is below it.
        double sigma_measured = 0.0;
        std::size_t removal_wanted = 0;  // returns steps 1-4 would have removed
        bool stale_references = false;   // step 5: temporal evidence ignored for this scan
        bool capped = false;             // step 5: spatial removal cut to the bound too
        bool recent = false;             // step 3b: the raw scan just before was used
        double recent_margin_m = 0.0;    // m: its margin's constant part (3 max(sqrt 2 sigma, s))
        bool recent_overruled = false;   // step 5: it wanted too much; the keyframes alone used
        bool confirmed = false;  // step 5: beyond the bound, confirmed by the raw scan just before
        bool next = false;       // step 3c: the raw scan just after was used
        std::size_t spikes = 0;  // step 4b: spikes removed
        std::size_t veils = 0;   // step 6: mixed pixels removed
        std::size_t surface_kept = 0;  // step 7: returns kept because they form a surface
    };

    EvidenceFilter() { initialize(Params{}); }
    explicit EvidenceFilter(const Params& p) { initialize(p); }
    void initialize(const Params& p);  // kfd::ParameterError on bad values
    const Params& params() const { return params_; }

    /// Where the tracker placed a scan (kfd/algorithms/scan_tracker.h, verdict Tracked): the
    /// robot's tracked pose and the RMS point-to-line residual of its alignment (m).
    struct Tracked {
        Pose2D pose;
        double rms_m = 0.0;
    };

    /// Filters the scan (clears the valid flag of removed returns); `out` receives the
    /// segments as clusters (label per beam, noise flag per segment).
    Result filter(Scan& scan, Clusters& out);
    /// The same with the sensor's next scan as a second raw reference (step 3c; `next` as the
    /// keyframe stage passed it on: dropped or kept, before its own denoising). nullptr or
    /// next_scan off: filter(scan, out). `next` is only read, during the call.
    Result filter(Scan& scan, Clusters& out, const Scan* next);
    /// The same, with where the tracker placed this scan (nullptr: not tracked). With
    /// track_alignment, a reference the tracker placed too is aligned by the two poses.
    Result filter(Scan& scan, Clusters& out, const Scan* next, const Tracked* tracked);
    /// Keeps a copy of a scan not filtered (one the keyframe stage dropped) as a temporal
    /// reference for the next keyframe (step 3b). Copies ranges, flags and odometry into a
    /// ring of temporal_scans preallocated slots: no allocation once they have grown, O(n).
    /// Does nothing when temporal_scans is 0 or temporal is off.
    void observe(const Scan& scan, const Tracked* tracked = nullptr);
    /// Forget the previous keyframe and the noise estimate (a new sensor or log).
    void reset();

    /// The residual of the middle of three returns at ranges a, r, b, res (rad) apart, against
    /// the line through the outer two, along its beam (step 1). NaN when a + b are degenerate.
    static double lineResidual(double a, double r, double b, double cos_res);
    /// atan2 to ~1e-5 rad (a 0.25-degree beam is 4.4e-3 rad) at a fraction of libm's cost.
    static float approxAtan2(float y, float x);

  private:
    enum Evidence : std::uint8_t { kUnknown = 0, kSupported = 1, kFree = 2, kTracked = 3 };
    // Where the tracker placed a kept scan's sensor (present = false: not tracked).
    struct SensorTrack {
        bool present = false;
        Pose2D pose;  // the sensor's tracked pose
        double rms_m = 0.0;
        static SensorTrack of(const Scan& scan, const Tracked* tracked);
    };
    // One of the last two keyframes: returns before removal, links, evidence, points, its
    // odometry pose and the pose refined by the chain of alignments (sensor frames).
    struct Reference {
        bool present = false;
        ScanGeometry geometry;
        std::vector<float> range, x, y;
        std::vector<std::uint8_t> valid, link, evidence;
        bool has_odom = false;
        Pose2D odom, pose;
        SensorTrack track;
    };
    // A raw scan kept for step 3b: copies, converted only when a keyframe comes.
    struct RawScan {
        ScanGeometry geometry;
        std::vector<float> range;
        std::vector<std::uint8_t> valid;
        bool has_odom = false;
        Pose2D odom;
        SensorTrack track;
        // Ranges, flags, odometry and tracked pose (buffers reused).
        void copy(const Scan& scan, const Tracked* tracked);
    };
    // A reference seen from this scan: the step and the margins (m0 + m1 x range).
    struct Projection {
        bool usable = false;
        float c = 1, s = 0, tx = 0, ty = 0, m0 = 0, m1 = 0;
        const Reference* ref = nullptr;
    };

    void updateTables(const ScanGeometry& g);
    // The scan's points in its sensor frame (x_, y_), the tables updated to its geometry.
    void toPoints(const Scan& scan);
    // Step 5: removal within the bound (steps 3-4 again on the keyframes alone, then without
    // temporal evidence, then the smallest segments first); whether temporal evidence stands.
    bool boundRemoval(const Scan& scan, Clusters& out, double sigma, std::size_t valid_in,
                      std::size_t cap, Result& res);
    double estimateSigma(const Scan& scan);
    // Step 2's breakpoint distance over r_min per beam step 1..max_step, and its noise term.
    struct Breakpoints {
        float factor[18] = {};
        float noise = 0.0f;
        std::size_t max_step = 1;
    };
    Breakpoints breakpoints(double sigma) const;
    // Step 2: segments of linked returns (linkNeighbours, labelSegments, joinAcrossSeam).
    void segment(const Scan& scan, double sigma, Clusters& out);
    // line_ (on a line with both neighbours) and link_ (one surface with the next beam).
    void linkNeighbours(const Scan& scan, double sigma, const Breakpoints& bp);
    // Sizes, range sums and flanked flags per segment, at least n each (labelSegments).
    void reserveSegmentBuffers(std::size_t n);
    // Labels segments across up to max_gap_beams missing beams; first and last valid beams
    // out (last = n without one); flanked_: another segment's return within max_gap_beams + 1.
    void labelSegments(const Scan& scan, const Breakpoints& bp, Clusters& out,
                       std::size_t& first_valid, std::size_t& last);
    // A scanner closing the circle: the last segment joins the first across the seam.
    void joinAcrossSeam(const Scan& scan, const Breakpoints& bp, std::size_t first_valid,
                        std::size_t last, Clusters& out);
    // `recent`: use the raw scans of step 3b (false: the keyframes only).
    bool temporalEvidence(const Scan& scan, const Clusters& out, double sigma, Result& res,
                          bool recent);
    // Step 3a: the newest keyframe seen from this scan (sets pose_; usable = false without it).
    Projection keyframeProjection(const Scan& scan, double sigma, Result& res);
    // The returns step 3 judges, in unknown_ with their points in batch_; returns how many.
    std::size_t listReturnsToJudge(const Clusters& out);
    // Evidence for the listed returns from the raw neighbours (pt, pn) and the keyframe (p0);
    // the ones left unknown are listed again in unknown_; returns how many.
    std::size_t judgeListed(const Clusters& out, std::size_t listed, const Projection& pt,
                            const Projection& pn, const Projection& p0, Result& res);
    // Support (never free space) from the older keyframe and the older raw scans.
    void supportFromOlder(const Scan& scan, const Clusters& out, double sigma, std::size_t unknowns,
                          bool recent, Result& res);
    Projection projection(const Reference& ref, const Pose2D& d, double sigma) const;
    std::uint8_t classify(const Projection& pr, float x, float y, bool free_test) const;
    // The same for the point (qx, qy) already in the reference's frame, at bracket position u.
    std::uint8_t classifyAt(const Projection& pr, float qx, float qy, float u,
                            bool free_test) const;
    // `spread` (optional): 1.4826 x the median |residual| of the last iteration's pairs (m).
    // `skip`: the schedule's first steps already done (by the tracker): not run, gate halved;
    // then `samples` returns per step (0: refine_samples).
    bool refineStep(const Scan& scan, const Reference& ref, Pose2D& d, double* spread = nullptr,
                    std::size_t skip = 0, std::size_t samples = 0) const;
    // refineStep's samples: every stride-th valid return's point into (sx, sy); how many.
    std::size_t sampleReturns(const Scan& scan, std::size_t stride, float* sx, float* sy) const;
    // refineStep's pairs: each projected sample (qx, qy at bracket position u in ref) within
    // `gate` of the reference segment bracketing it, added to `sys`, its |distance| to
    // `residuals`; returns how many.
    static std::size_t pairWithLines(const Reference& ref, std::size_t m, const float* qxs,
                                     const float* qys, const float* us, float gate,
                                     PointToLineSystem<float>& sys, float* residuals);
    // Step 3b: the newest raw scan as a projection (usable = false when it cannot be used).
    // Steps 3b/3c: a converted raw scan aligned from odometry (or zero motion) and its margin
    // from the alignment (`base`: 3 max(sqrt 2 sigma, s)); usable = false without one.
    Projection rawProjection(const Scan& scan, const Reference& ref, double sigma,
                             double* base) const;
    Projection recentProjection(const Scan& scan, std::size_t age, double sigma, Result& res);
    // Converts raw scan `age` (0 = newest) into recent_ (points, breakpoint links).
    bool convertRaw(const Scan& scan, std::size_t age, double sigma);
    // Converts raw scan `w` into `r` (convertRaw's work, for any slot).
    bool convertInto(const RawScan& w, Reference& r, const Scan& scan, double sigma);
    // Step 3c: the next scan (next_) as a projection, converted into next_ref_.
    Projection nextProjection(const Scan& scan, double sigma, Result& res);
    void keepRaw(const Scan& scan, const Tracked* tracked);
    // With track_alignment (or track_raw_alignment and a raw reference), where both this scan
    // (tracked_) and `ref` were tracked: d = this scan's sensor in ref's frame from the two
    // tracked poses, and true.
    bool trackedStep(const Scan& scan, const Reference& ref, Pose2D& d, bool raw) const;
    // Where both this scan and `ref` were tracked: d from the two tracked poses, and true.
    bool placedByTracker(const Scan& scan, const Reference& ref, Pose2D& d) const;
    bool trackedMotion(const Reference& ref, float qx, float qy, float rho, std::size_t k0) const;
    void keepAsReference(const Scan& scan);
    // Step 4: marks noise segments; returns the returns it would remove.
    std::size_t markNoise(Clusters& out, bool temporal);
    // Step 5: removals beyond the bound that the raw scan just before confirms.
    bool confirmedByRecent(const Clusters& out, std::size_t valid_in, std::size_t wanted) const;
    static constexpr std::size_t kMinConfirmJudged = 16;  // returns judged outside the removal
    // Step 5: the smallest noise segments only, up to `cap` returns.
    void capNoise(Clusters& out, std::size_t cap);
    /// Steps 5-7 applied: marked segments and free returns removed, spikes (4b) and mixed
    /// pixels (6) too, surfaces kept (7). `valid_in`: the scan's valid returns (step 4's count).
    void removeMarked(Scan& scan, const Clusters& out, const std::vector<std::uint8_t>& kept_ev,
                      bool temporal, double sigma, std::size_t valid_in, std::size_t cap,
                      Result& res);
    // Step 4b: marks spikes in remove_; returns how many (none when they would take the scan's
    // removal beyond `cap`).
    std::size_t markSpikes(const Scan& scan, const std::vector<std::uint8_t>& kept_ev,
                           bool temporal, std::size_t cap);
    // Step 4b's geometry, before step 3: the returns off both neighbours' ranges by the pair
    // margin where the neighbours are one surface across them, off a line (spike_candidates_).
    void findSpikeCandidates(const Scan& scan, double sigma);
    // Step 4b (spike_object_support): marks in object_support_ the supported candidates that
    // pr's reference saw an object at.
    void markObjectSupport(const Projection& pr);
    // A return of pr's reference within the support margin of (qx, qy) (its frame, bracket
    // position u) that is not inside a smooth surface: off a neighbour's range by more than
    // the pair margin, or beside a dropout or the scan's end.
    bool objectSupported(const Projection& pr, float qx, float qy, float u) const;
    // Returns `cap` less the valid returns remove_ already holds (0 when at or past it).
    std::size_t roomUnderBound(const Scan& scan, std::size_t cap) const;
    // Step 6: marks mixed pixels in remove_ (none when they would take the scan's removal
    // beyond `cap`); returns the count.
    std::size_t markVeils(const Scan& scan, const Clusters& out, double sigma, std::size_t cap);
    // Step 6: marks in veil_ the mixed pixels at a segment's first (`last` false) or last
    // beam `end`, walking inward.
    void veilAtEnd(const Scan& scan, const Clusters& out, std::size_t end, bool last, double sigma);
    // Step 6: marks in veil_ the short runs between a nearer and a farther return.
    void veilRuns(const Scan& scan, double sigma);
    // The nearest valid beam before (after) i within max_gap_beams + 1 beams; n when none.
    std::size_t neighbourReturn(const Scan& scan, std::size_t i, bool after) const;
    static constexpr std::size_t kMaxVeil = 8;  // returns at most at a segment's end (step 6)

    Params params_;
    double lambda_ = 0.0;
    BeamDirections dirs_;
    float first_ = 0.0f, inv_step_ = 0.0f, res_ = 0.0f;  // of the scan's geometry
    std::vector<float> x_, y_;                           // this scan's points (sensor frame)
    std::vector<float> scratch_;                         // residuals sampled for the noise quantile
    std::vector<std::uint8_t> line_;      // per beam: on a line with its two neighbours
    std::vector<std::uint8_t> link_;      // per beam: one surface with the next return
    std::vector<std::uint8_t> evidence_;  // per beam: Evidence
    std::vector<float> sums_;             // per segment: range sum (kept at its largest)
    std::vector<std::uint32_t> sizes_;    // per segment: returns (labelSegments' buffer)
    std::vector<std::uint32_t> unknown_;  // beams classified unknown against the newest keyframe
    std::vector<float> batch_;            // returns to classify: points, projections, brackets
    std::vector<std::uint32_t> free_in_, supported_in_, classified_in_;  // per segment
    std::vector<std::uint32_t> free_off_line_in_;  // per segment: free returns off a line
    std::vector<std::uint32_t> order_;             // segments by size
    std::vector<std::uint8_t> small_;              // per segment: small
    std::vector<std::uint8_t> flanked_;            // per segment: another's return beside it
    std::vector<std::uint8_t> remove_;             // per beam: to be removed (steps 4-7)
    std::vector<std::uint8_t> noise_by_label_;     // per label + 1: out.noise (0 for no return)
    std::vector<std::uint8_t> veil_;               // per beam: a mixed pixel (step 6)
    std::vector<std::uint32_t> spikes_;            // the spikes' beams (step 4b)
    std::vector<std::uint8_t> off_;  // per beam: off both neighbours' ranges (step 4b)
    std::vector<std::uint32_t> spike_candidates_;      // step 4b's beams before the evidence
    std::vector<std::uint8_t> object_support_;         // per candidate: a reference saw an object
    float spike_margin_ = 0.0f;                        // step 4b's pair margin (m)
    std::vector<std::uint32_t> seg_first_, seg_last_;  // per segment: its first and last beam
    double sigma_smoothed_ = -1.0;
    double measured_smoothed_ = -1.0;       // the same, of the estimates before the floor
    Reference refs_[2];                     // [0] the newest keyframe
    std::vector<RawScan> raw_;              // step 3b: ring of temporal_scans raw scans
    std::size_t raw_next_ = 0;              // the slot the next raw scan goes to
    std::size_t raw_count_ = 0;             // raw scans held
    Reference recent_;                      // a raw scan converted for this keyframe
    std::vector<std::uint8_t> recent_ev_;   // per beam: the raw scan just before's verdict
    const Scan* next_ = nullptr;            // step 3c: the next scan, during filter() only
    const Tracked* tracked_ = nullptr;      // this scan's tracked pose, during filter() only
    RawScan next_raw_;                      // its copy (reused buffers)
    Reference next_ref_;                    // converted
    mutable std::vector<float> residuals_;  // refineStep's last iteration |e|
    mutable std::vector<float> align_;      // refineStep's samples, projections, brackets
    Pose2D pose_;                           // this scan's refined pose (when have_pose_)
    bool have_pose_ = false;
};

}  // namespace kfd
