// Odometry sanity (issue 22): odometry that contradicts the scans is not used. Std only.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// What the odometry check decided for one scan.
enum class OdometryVerdict {
    None,    // the scan came without odometry
    Ok,      // used as given (after any earlier jump was taken out)
    Frozen,  // odometry stood still while the scans changed: not used (laser only)
    Jump,    // odometry moved where the scans did not: not used, later odometry rebased
};
/// "none", "ok", "frozen", "jump".
const char* toString(OdometryVerdict v);

/// Checks each scan's odometry against the scans themselves and withholds what they contradict,
/// so that every later stage (keyframe guards, view selector, the denoiser's temporal evidence)
/// falls back to laser-only decisions for that stretch.
///
/// Why: a laser-only log converted to a rawlog carries all-zero odometry (MRPT's converters
/// write it). On a real log of a walking sensor, kfd believed "no motion", kept one scan per
/// ~1.2 s and the denoiser removed half of a kept scan's returns (issue 22).
///
/// Both tests compare ranges beam by beam on sampled beams, with the view selector's per-beam
/// change tolerance (tolerance_m + tolerance_ratio x range: sensor noise stays under it, motion
/// does not); the shares they compare are measured on the scans, not tuned per sensor.
///  - Frozen: while the odometry does not move (below still_m and still_deg per scan), the
///    scan is compared with the first scan of that still stretch. Once more than
///    frozen_changed_fraction of the beams both saw changed, the sensor moved: the odometry
///    is frozen, and withheld until it moves again.
///  - Jump: a step of odometry far beyond the log's own pace (more than jump_pace_factor times
///    the median speed of the last steps, in translation or rotation, plus one tolerance) is
///    tested against the previous scan: the previous points moved by the step, and left where
///    they were, are compared with this scan's surface between the beams bracketing them. When
///    standing still explains jump_margin more of the previous returns than the step does,
///    the step is a jump: this scan gets no odometry, and later odometry is rebased so that the
///    jump is taken out (the pose carries on from the previous scan). Steps at the log's pace
///    are never tested: on the Freiburg logs a test of every step flagged ordinary 0.1 m steps
///    (a point between beams on a grazing wall; docs/CHANGELOG.md).
/// A corridor (where moving along it changes no beam) passes both tests: nothing contradicts.
class OdometryCheck {
  public:
    struct Params {
        std::size_t max_samples = 128;         // beams compared: every k-th
        double tolerance_m = 0.05;             // a beam changed beyond this ...
        double tolerance_ratio = 0.02;         // ... plus this share of its range
        double still_m = 1e-4;                 // m: odometry "does not move" below this per scan
        double still_deg = 0.01;               // deg: the same, in rotation
        double frozen_changed_fraction = 0.3;  // frozen beyond this share of changed beams
        double jump_margin = 0.3;              // jump: still explains this share more
        double jump_pace_factor = 3.0;         // jump candidates: beyond this x the median pace
        std::size_t pace_steps = 32;           // steps in the median pace
        std::size_t min_beams = 20;            // beams both saw, fewer: no test
    };

    struct Result {
        OdometryVerdict verdict = OdometryVerdict::None;
        double changed_fraction = 0.0;  // frozen test: share changed since the still stretch began
        double agree_still = 0.0;       // jump test: share explained by no motion ...
        double agree_odometry = 0.0;    // ... and by the odometry step
    };

    OdometryCheck() { initialize(Params{}); }
    explicit OdometryCheck(const Params& p) { initialize(p); }
    void initialize(const Params& p);  // kfd::ParameterError on bad values
    const Params& params() const { return params_; }
    void reset();

    /// Checks the scan's odometry; clears it (Frozen, Jump) or replaces it with the rebased
    /// odometry (after a jump). Scans without odometry pass unchanged.
    Result check(Scan& scan);

  private:
    struct Samples {  // sampled beams of a scan
        ScanGeometry geometry;
        std::vector<float> range;  // NaN = no return
        Pose2D sensor;
    };
    void sample(const Scan& scan, Samples& out) const;
    double changedFraction(const Samples& a, const Samples& b, std::size_t& both) const;
    // Share of `from`'s points that land on a matching beam of `to` when moved by `step`
    // (robot frame); `seen` counts the points that land on a valid beam.
    double agreement(const Samples& from, const Scan& to, const Pose2D& step,
                     std::size_t& seen) const;

    Params params_;
    double still_rad_ = 0.0;
    Samples prev_, anchor_, cur_;
    bool have_prev_ = false, have_anchor_ = false, frozen_ = false;
    bool beyondPace(const Pose2D& step, double dt);
    std::optional<Pose2D> prev_raw_;  // the previous scan's odometry as given
    double prev_stamp_ = 0.0;
    std::vector<double> pace_m_, pace_rad_, sorted_;  // recent steps' speeds (per s or per step)
    Pose2D correction_;                               // rebased = correction (+) raw
};

}  // namespace kfd
