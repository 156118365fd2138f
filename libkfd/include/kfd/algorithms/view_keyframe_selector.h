// kfd's keyframe rule (issue 12): a scan is a keyframe when the view moved beyond the last
// keyframe's (ViewSelector), plus the guards both keyframe stages share. std only.
#pragma once

#include "kfd/algorithms/keyframe_guards.h"
#include "kfd/algorithms/scan_tracker.h"
#include "kfd/algorithms/view_selector.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// The `view_keyframe` stage's algorithm (kfd's default): ViewSelector decides whether the
/// view moved beyond the last keyframe's; KeyframeGuards force a keyframe after too many
/// drops, too long, too far or too much turn.
class ViewKeyframeSelector {
  public:
    struct Params : KeyframeGuards::Params {
        ViewSelector::Params view;
    };

    ViewKeyframeSelector() { initialize(Params{}); }
    explicit ViewKeyframeSelector(const Params& p) { initialize(p); }
    /// Validates (kfd::ParameterError naming the field), then resets.
    void initialize(const Params& p);
    const Params& params() const { return params_; }
    void reset();

    /// Decides on the scan (does not modify it). With the scan's track (the track stage ran
    /// before): the view change is measured from the tracked motion since the keyframe, a scan
    /// the tracker could not align is a keyframe (track_poor), and so is one whose tracked
    /// motion and odometry disagree by max_track_disagreement (track_odometry).
    KeyframeDecision filter(const Scan& scan, const TrackResult* track = nullptr);

  private:
    bool disagrees(const Scan& scan, const TrackResult* track) const;

    Params params_;
    ViewSelector view_;
    KeyframeGuards guards_;
};

}  // namespace kfd
