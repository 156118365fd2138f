// Fused keyframes (issue 25, kfd's, beyond the paper): a keyframe's ranges replaced by a robust
// estimate over the scans dropped since the previous keyframe (std only).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// The keyframe stage drops most scans; those since the previous keyframe are repeated views
/// of the same surfaces, and averaging repeated returns lowers range noise.
///
/// observe() copies a dropped scan (ranges, valid flags, sensor pose by odometry) into a ring
/// of max_scans preallocated slots (the newest replace the oldest): a copy of its ranges, no
/// allocation once the slots have grown. A scan without odometry is not kept (laser-only logs:
/// nothing is fused); a new geometry empties the ring.
///
/// fuse(keyframe), per keyframe (S kept scans, n beams, O(S n), no allocation in steady state):
///  1. Range noise sigma from the keyframe, as the evidence denoiser measures it: the lower
///     decile of the residuals of every fourth beam against its neighbours' line
///     (EvidenceFilter::lineResidual), / (0.1257 sqrt(1.5)), floored at min_sigma_m and
///     smoothed over keyframes (0.8 / 0.2).
///  2. Each kept scan within max_step_m / max_step_deg of the keyframe (odometry) is moved
///     into the keyframe's sensor frame, the step refined by a projective point-to-line
///     alignment (refine_iterations x refine_samples returns, against the keyframe's segments
///     between neighbouring returns on one surface); each pair of neighbouring returns on one
///     surface (the adaptive breakpoint of the evidence filter, lambda 10 deg, + 3 sqrt(2) sigma)
///     that spans keyframe beams (at most max_span_beams) gives, for each of them, the range where
///     the beam meets the segment between the two (the nearer when two segments meet a beam).
///  3. A return agrees when within gate = gate_sigmas sqrt(2) sigma of the keyframe's own
///     range (the difference of two returns has sigma sqrt(2) sigma). A scan whose agreeing
///     returns are off by more than max_bias_sigmas sigma in the median (odometry error
///     between it and the keyframe), or that has fewer than 16 of them, takes no part.
///  4. A valid beam with at least min_agreeing agreeing returns gets the median (or the mean,
///     estimator) of its own range and theirs; the others keep theirs; invalid beams stay
///     invalid. The ring is emptied: nothing is fused across keyframes, a reset or a new
///     geometry.
class ScanFusion {
  public:
    enum class Estimator { Median, Mean };

    struct Params {
        std::size_t max_scans = 8;     // dropped scans kept between keyframes (the newest)
        std::size_t min_agreeing = 2;  // agreeing returns of dropped scans a beam needs
        double gate_sigmas = 3.0;      // gate = gate_sigmas x sqrt(2) x sigma (m)
        double max_bias_sigmas = 1.0;  // a scan off by more (median, x sigma) takes no part
        Estimator estimator = Estimator::Median;  // of the keyframe's and the agreeing returns
        double min_sigma_m = 0.005;      // m: floor of the noise estimate (range quantisation)
        double max_step_m = 1.0;         // m: dropped scans farther from the keyframe: not used
        double max_step_deg = 20.0;      // deg: the same, in rotation
        std::size_t max_span_beams = 4;  // keyframe beams one segment of a dropped scan may span
        /// Gauss-Newton steps aligning each dropped scan to the keyframe (point to line, as the
        /// evidence filter aligns to its keyframe) before the gate; 0 = odometry only.
        std::size_t refine_iterations = 3;
        std::size_t refine_samples = 96;  // returns used per step, at most (every ceil(n/96)-th)
        double refine_gate_m = 0.2;       // m: pairing gate of the first step (halved after)
    };

    /// Diagnostics of one keyframe.
    struct Result {
        std::size_t beams_fused = 0;        // valid beams whose range was replaced
        std::size_t beams_valid = 0;        // valid beams of the keyframe
        std::size_t scans_kept = 0;         // dropped scans in the ring at this keyframe
        std::size_t scans_used = 0;         // of those, the ones that took part
        std::size_t scans_misaligned = 0;   // rejected by the median-bias test (step 3)
        std::size_t scans_refined = 0;      // whose odometry step the alignment changed
        double mean_scans_per_fused = 0.0;  // agreeing returns per fused beam (without its own)
        double sigma = 0.0;                 // m: range noise used (step 1)
    };

    ScanFusion() { initialize(Params{}); }
    explicit ScanFusion(const Params& p) { initialize(p); }
    void initialize(const Params& p);  // kfd::ParameterError on bad values
    const Params& params() const { return params_; }

    /// Keeps a dropped scan for the next keyframe (cheap: a copy).
    void observe(const Scan& scan);
    /// Fuses the kept scans into the keyframe's valid ranges, then forgets them.
    Result fuse(Scan& keyframe);
    /// Forget the kept scans and the noise estimate.
    void reset();
    /// Dropped scans kept now.
    std::size_t kept() const { return count_; }

    /// The scan's own noise estimate (step 1, before floor and smoothing): the lower decile of
    /// |residual| over every `stride`-th beam / (0.1257 sqrt(1.5)); 0 with fewer than 16
    /// residuals. `scratch` is reused.
    static double measureSigma(const Scan& scan, std::size_t stride, std::vector<float>& scratch);

  private:
    struct Slot {
        std::vector<float> range;
        std::vector<std::uint8_t> valid;
        ScanGeometry geometry;
        Pose2D pose;  // sensor pose by odometry
    };

    // Refines d (the dropped scan's sensor in the keyframe's frame) against the keyframe's
    // points kx_, ky_ and links; true when it changed.
    bool refine(const Scan& kf, const Slot& slot, Pose2D& d) const;

    // One keyframe's frame: geometry, angle table origin, the noise gates and the breakpoint.
    struct Frame {
        ScanGeometry g;
        float first = 0.0f, inv_step = 0.0f;  // beam index u = (angle - first) * inv_step
        std::size_t S = 0;                    // cand_'s columns (max_scans)
        Pose2D kf_pose;                       // the keyframe's sensor by odometry
        double sigma = 0.0;                   // m
        float gate = 0.0f, noise = 0.0f, factor = 0.0f, span = 0.0f;
    };
    // fuse()'s steps (scan_fusion.cpp says what each does).
    Frame frameOf(const Scan& kf, double sigma);
    void keyframeSurfaces(const Scan& kf, const Frame& f);
    void project(const Slot& slot, const Pose2D& d, std::size_t s, const Frame& f);
    bool agreesWithKeyframe(const Scan& kf, std::size_t s, const Frame& f, Result& res);
    void combine(Scan& kf, std::size_t kept, const Frame& f, Result& res) const;

    Params params_;
    std::vector<Slot> slots_;
    std::size_t head_ = 0, count_ = 0;  // next slot to write, slots filled
    BeamDirections dirs_;
    std::vector<float> cand_;          // n x max_scans: range of scan s at beam k
    std::vector<float> qx_, qy_, u_;   // a dropped scan's points in the keyframe's frame
    std::vector<float> kx_, ky_;       // the keyframe's points
    std::vector<std::uint8_t> klink_;  // per keyframe beam: one surface with the next
    std::vector<float> scratch_;       // residuals, differences
    std::vector<std::uint8_t> used_;   // per slot: takes part
    double sigma_smoothed_ = -1.0;
};

/// "median" or "mean"; kfd::ParameterError("fuse_estimator") otherwise.
ScanFusion::Estimator parseFusionEstimator(const std::string& text);
const char* toString(ScanFusion::Estimator e);

}  // namespace kfd
