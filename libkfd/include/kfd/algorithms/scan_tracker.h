// kfd's scan tracker (issue 35): every scan, kept or dropped, aligned to the current keyframe by
// a robust point-to-line alignment, so that a dropped scan is not blind and the next keyframe's
// scan matching starts from where the scans say the robot is. std only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "kfd/pipeline/scan.h"

namespace kfd {

/// How a scan's pose relative to its keyframe was found.
enum class TrackVerdict : std::uint8_t {
    First,       // no keyframe yet (or a new geometry): the scan starts the track
    Tracked,     // aligned: the offset is the scans'
    Degenerate,  // the fit leaves a direction unconstrained (a corridor): the prior is kept
    Poor,        // too little overlap, or residuals spread over the gate: the prior is kept
};
const char* toString(TrackVerdict v);

/// One scan's track. Poses are the robot's (the sensor mount removed), metres and radians.
struct TrackResult {
    TrackVerdict verdict = TrackVerdict::First;
    bool odometry_prior = false;  // the prior came from odometry (else constant velocity)
    std::uint16_t iterations = 0;
    std::uint16_t pairs = 0;    // point-line pairs of the last iteration
    float overlap = 0.0f;       // share of the sampled returns paired in the last iteration
    float rms_m = 0.0f;         // RMS point-to-line distance of those pairs (m)
    float conditioning = 0.0f;  // lambda_min / lambda_max of the translation information
    Pose2D offset;              // the robot relative to its keyframe: tracked, else the prior
    Pose2D prior;               // the prior relative to the keyframe
    Pose2D pose;                // the track: the keyframe's tracked pose (+) offset

    bool tracked() const { return verdict == TrackVerdict::Tracked; }
};

/// Aligns each scan to the last keyframe: projective point-to-line Gauss-Newton (each sampled
/// return projected into the keyframe and paired with the keyframe segment between its two
/// bracketing beams, when they are one surface), the pairing gate halving from gate_m down to
/// min_gate_m, until the step is below 0.1 mm and 0.006 degrees. The prior is the odometry
/// since the keyframe when both scans have it, else the last scan's offset plus the last
/// inter-scan motion (constant velocity). The verdict gates the fit on its overlap, its
/// residuals and the conditioning of its translation. When the prior's fit is poor (odometry
/// slipping or glitching in a turn, constant velocity after a wrong step) the fit is tried
/// again from constant velocity (after an odometry prior), then from the last scan's offset,
/// and the first that passes is taken. A fit that fails keeps the prior; without odometry
/// constant velocity then stops (the next prior is the last offset).
///
/// The track (TrackResult::pose) starts at the first scan's odometry (the origin without it)
/// and composes every keyframe's offset: a laser odometry in the odometry's frame.
class ScanTracker {
  public:
    struct Params {
        std::size_t max_samples = 96;      // returns aligned: every k-th beam, k = ceil(n / this)
        std::size_t max_iterations = 12;   // Gauss-Newton steps at most
        double gate_m = 0.4;               // first pairing gate (m); halves per step ...
        double min_gate_m = 0.1;           // ... down to this (m)
        double min_overlap = 0.5;          // Poor below this share of paired samples
        double max_spread = 0.4;           // Poor when RMS > this x the final gate (0.58: uniform)
        double min_conditioning = 0.02;    // Degenerate below this lambda_min / lambda_max
        double link_incidence_deg = 10.0;  // two neighbouring returns are one surface unless
                                           // their gap needs an incidence below this
    };

    ScanTracker() { initialize(Params{}); }
    explicit ScanTracker(const Params& p) { initialize(p); }
    /// Validates (kfd::ParameterError naming the field), applies, resets.
    void initialize(const Params& p);
    const Params& params() const { return params_; }
    /// Forgets the keyframe and the track.
    void reset();

    /// Aligns the scan to the keyframe (does not change it).
    TrackResult track(const Scan& scan);
    /// The scan track() saw last becomes the keyframe, its returns as track() saw them (a
    /// later stage's removals do not count, so one scan of latency changes nothing).
    void accept();

    bool hasKeyframe() const { return have_keyframe_; }

  private:
    struct Fit {
        Pose2D d;  // sensor frame: scan -> keyframe
        std::size_t iterations = 0, pairs = 0, samples = 0;
        double rms = 0.0, gate = 0.0, conditioning = 0.0;
    };
    Fit align(const Scan& scan, const Pose2D& prior_sensor);
    TrackVerdict verdictOf(const Fit& f) const;  // the gates on overlap, spread, conditioning
    static float overlapOf(const Fit& f);
    Pose2D prior(const Scan& scan, bool& from_odometry) const;
    void keyframeLines();

    Params params_;
    double sin_incidence_ = 0.0;
    BeamDirections dirs_;
    std::vector<float> px_, py_;  // the scan's sampled returns (sensor frame)
    // the keyframe: its returns, and per segment (k, k+1) when one surface (link_) the unit
    // normal and a point of its line (the chord of the surface around it)
    bool have_keyframe_ = false, started_ = false;
    ScanGeometry kf_geometry_;
    std::vector<float> kx_, ky_, nx_, ny_, ax_, ay_;
    std::vector<std::uint8_t> link_;
    std::optional<Pose2D> kf_odometry_;
    Pose2D kf_pose_;   // the keyframe's tracked pose
    Pose2D kf_mount_;  // its sensor pose on the robot
    // constant velocity: the last scan's offset and the motion between the last two scans
    Pose2D last_offset_, velocity_;
    TrackResult last_;  // the last track() result (accept() makes its scan the keyframe)
    Scan candidate_;    // the scan track() saw last, as it saw it
};

}  // namespace kfd
