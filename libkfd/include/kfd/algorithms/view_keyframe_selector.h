// kfd's keyframe rule (issue 12): a scan is a keyframe when the view moved beyond the last
// keyframe's (ViewSelector), plus the guards both keyframe stages share. std only.
#pragma once

#include "kfd/algorithms/keyframe_guards.h"
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

    /// Decides on the scan (does not modify it).
    KeyframeDecision filter(const Scan& scan);

  private:
    Params params_;
    ViewSelector view_;
    KeyframeGuards guards_;
};

}  // namespace kfd
