// What a keyframe stage decided about one scan, and the guards both keyframe stages share
// (beyond the paper; each 0 = off, all off in the paper presets). std only.
#pragma once

#include <string_view>

#include <cstddef>
#include <cstdint>
#include <optional>

#include "kfd/pipeline/scan.h"

namespace kfd {

/// Why a scan was kept or dropped.
enum class KeyframeReason : std::uint8_t {
    First,          // first scan of the stream (or after reset): always a keyframe
    Dissimilar,     // P_common < P_threshold (Formula 3): new information
    MaxDrops,       // guard: too many consecutive drops
    MaxInterval,    // guard: too long since the last keyframe
    Translation,    // guard: odometry moved too far since the last keyframe
    Rotation,       // guard: odometry turned too far since the last keyframe (rotation in place)
    Similar,        // P_common >= P_threshold: dropped
    ViewChange,     // view selector: the view moved beyond the keyframe's
    Corridor,       // view selector, degenerate scene: odometry (or time) since the keyframe
    Covered,        // view selector: the keyframe covers this view: dropped
    TrackPoor,      // view selector, tracker: the scan no longer aligns with the keyframe
    TrackOdometry,  // view selector, tracker: the scans moved where the odometry does not
};
const char* toString(KeyframeReason r);
/// What a reason means, in one phrase for summaries ("dropped: the last keyframe still covers
/// the view ..."); `name` is toString()'s text; nullptr for a name that is no KeyframeReason.
const char* describeKeyframeReason(std::string_view name);

/// Outcome of one keyframe decision, with diagnostics (the keyframe and view_keyframe stages').
struct KeyframeDecision {
    bool keyframe = true;
    KeyframeReason reason = KeyframeReason::First;
    double p_common = 0.0;        // product of clamped correlations with the window (Formula 3)
    double p_threshold = 0.0;     // P_pair^k, k = references compared
    double min_similarity = 0.0;  // the weakest pairwise similarity in the window
    std::size_t references = 0;   // k: keyframes compared against (<= window)
    std::size_t consecutive_drops = 0;  // drops since the last keyframe, this one included
    // the view selector's measures (view_keyframe stage; 0 / 1 / false otherwise)
    double view_change = 0.0;       // RMS displacement since the keyframe, in tolerances
    double changed_fraction = 0.0;  // laser only: share of common returns that changed
    double degeneracy = 1.0;        // lambda_min / lambda_max of the normals' information
    bool corridor = false;          // degeneracy below the switch's ratio
};

/// Guards force a keyframe even when the scan looks similar; the paper has none, and without
/// them a robot rotating in place in a symmetric room, standing still for minutes, or driving
/// down a featureless corridor would produce no keyframe at all.
class KeyframeGuards {
  public:
    struct Params {
        std::size_t max_consecutive_drops = 40;  // K: force a keyframe after K drops in a row
        double max_interval_s = 2.0;             // T (s) since the last keyframe
        double max_translation_m = 0.5;          // D (m) of odometry travel since the last keyframe
        double max_rotation_deg = 15.0;          // A (deg) of odometry turn since the last keyframe
    };

    /// Validates (kfd::ParameterError naming the field) and resets.
    void initialize(const Params& p);
    void reset();
    /// A scan the rule dropped: a guard that fires makes it a keyframe (d.reason says which),
    /// in order of precedence: drops, interval, translation, rotation.
    void apply(KeyframeDecision& d, double timestamp, const std::optional<Pose2D>& odometry) const;
    /// Updates the drop count and, for a keyframe, the reference stamp and odometry; sets
    /// d.consecutive_drops.
    void record(KeyframeDecision& d, double timestamp, const std::optional<Pose2D>& odometry);

  private:
    Params params_;
    std::size_t drops_ = 0;  // consecutive drops since the last keyframe
    double last_stamp_ = 0.0;
    bool have_stamp_ = false;
    std::optional<Pose2D> last_odometry_;
};

}  // namespace kfd
