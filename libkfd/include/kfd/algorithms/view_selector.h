// kfd's view selector (issue 12): keyframes by how far the view moved, beside the paper's
// histogram correlation (keyframe_selector.h), with the corridor switch of the paper's
// future work (Sec. 5). Std only.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// What the view selector measured on one scan.
struct ViewMeasure {
    bool keyframe = true;        // the view moved beyond the keyframe's (or no keyframe yet)
    bool corridor = false;       // geometrically degenerate: the switch decided (odometry or time)
    bool used_odometry = false;  // view_change from odometry (else changed_fraction decided)
    double view_change = 0.0;    // how far the view moved since the keyframe (see below)
    double changed_fraction = 0.0;  // share of the returns both saw whose range changed
    double degeneracy = 1.0;        // lambda_min / lambda_max of the normals' information [0, 1]
};

/// Decides whether a scan shows a view the last keyframe does not cover.
///
/// With odometry: the relative motion T = (R, t) since the keyframe. A translation moves every
/// point by |t| whatever its range, counted in units of a; a rotation phi moves a point p at
/// range r by |(R - I) p| = 2 sin(phi / 2) r, counted in units of its tolerance a + r tan(b)
/// (a scan matcher's correspondence gate grows the same way). The view change is
///   sqrt( |t|^2 / a^2 + mean_p |(R - I) p|^2 / (a + r tan b)^2 )
/// over the sampled points (robot frame, sensor mount applied), a keyframe at max_view_change.
/// The mean has a closed form, 2 (1 - cos phi) sum w |p|^2 / n with w = 1 / (a + r tan b)^2,
/// so no point is transformed. Near walls a turn counts little, in a wide hall it counts as
/// much as it moves the far points. (A first form that also divided the translation by
/// a + r tan b let the robot drive far in open spaces and lost to the motion filter: see
/// docs/CHANGELOG.md, issue 12.)
///
/// Without odometry: the share of sampled beams, valid in both, whose range changed by more
/// than change_tolerance_m + change_tolerance_ratio * r since the keyframe (a per-beam change
/// test; sensor noise stays under the tolerance, motion does not).
///
/// Corridor switch: the information of point-to-line constraints on translation is
/// N = sum n n^T over the unit normals n of the sampled surface; in a corridor every normal
/// points across it and lambda_min(N) / lambda_max(N) -> 0. Below degeneracy_ratio the view
/// says nothing about motion along the corridor, so keyframes follow odometry
/// (corridor_translation_m, corridor_rotation_deg) or, without it, time (corridor_interval_s).
class ViewSelector {
  public:
    struct Params {
        std::size_t max_samples = 128;     // beams sampled: every k-th, k = ceil(beams / this)
        double tolerance_m = 0.3;          // a (m): displacement unit of a point at range 0
        double tolerance_deg = 5.0;        // b (deg): the unit grows by r tan(b) at range r
        double max_view_change = 0.75;     // keyframe at this view change (Formula in the header)
        double change_tolerance_m = 0.05;  // laser only: a range changed beyond this ...
        double change_tolerance_ratio = 0.02;  // ... plus this share of the range
        double max_changed_fraction = 0.3;     // laser only: keyframe at this changed share
        double degeneracy_ratio = 0.15;        // corridor below this (0 = switch off)
        double corridor_translation_m = 0.5;   // corridor with odometry: keyframe after this
        double corridor_rotation_deg = 15.0;   // ... or this turn
        double corridor_interval_s = 0.2;      // corridor without odometry: after this time
        // With a track (the tracker's motion since the keyframe): a keyframe when the track and
        // the odometry disagree by this view change (units as max_view_change; 0 = off).
        double max_track_disagreement = 0.5;
    };

    ViewSelector() { initialize(Params{}); }
    explicit ViewSelector(const Params& p) { initialize(p); }

    /// Validates (kfd::ParameterError naming the field) and applies, then resets.
    void initialize(const Params& p);
    const Params& params() const { return params_; }
    /// Forgets the keyframe.
    void reset();

    /// Measures the scan against the keyframe (odometry used when both have it; `motion`, the
    /// robot's motion since the keyframe as the tracker found it, instead when given). Does not
    /// change the keyframe: call accept() when the scan becomes one.
    ViewMeasure measure(const Scan& scan, const std::optional<Pose2D>& motion = std::nullopt);
    /// The view change (the formula above) of a robot motion `rel`, over the returns the last
    /// measure() sampled (0 before any).
    double viewChange(const Pose2D& rel, const Pose2D& sensor_pose) const;
    /// The odometry's motion since the keyframe, when both have odometry.
    std::optional<Pose2D> odometrySinceKeyframe(const Scan& scan) const;
    /// Makes the scan the keyframe (its sampled ranges, odometry and stamp).
    void accept(const Scan& scan);

    bool hasKeyframe() const { return have_keyframe_; }

  private:
    /// k: every k-th beam is sampled, k = ceil(beams / max_samples) (at least 1).
    std::size_t stride(std::size_t beams) const;
    // Every k-th return: weighted moments, tangent scatter, and (compare) the changed ranges.
    struct Samples {
        float w_sum = 0, wx = 0, wy = 0, wq = 0;  // moments (sensor frame; float: <= max_samples)
        float sxx = 0, sxy = 0;  // scatter of the unit tangents (syy = tangents - sxx)
        std::size_t points = 0, tangents = 0, both = 0, changed = 0;
    };
    Samples sample(const Scan& scan, std::size_t k, bool compare) const;
    static double degeneracyOf(const Samples& s);  // lambda_min / lambda_max (1: too few)
    void decideByOdometry(const Scan& scan, const std::optional<Pose2D>& motion,
                          ViewMeasure& m) const;
    void decideByChange(const Scan& scan, bool compare, const Samples& s, ViewMeasure& m) const;

    Params params_;
    double tan_b_ = 0.0;
    BeamDirections dirs_;
    // the keyframe
    bool have_keyframe_ = false;
    ScanGeometry kf_geometry_;
    std::vector<float> kf_samples_;  // sampled ranges, NaN = no return
    std::optional<Pose2D> kf_odometry_;
    double kf_stamp_ = 0.0;
    bool kf_have_stamp_ = false;
    // the last measure()'s weighted moments of the sampled returns (sensor frame)
    double w_sum_ = 0.0, wx_ = 0.0, wy_ = 0.0, wq_ = 0.0;
    std::size_t points_ = 0;
};

}  // namespace kfd
