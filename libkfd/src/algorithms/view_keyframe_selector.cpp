#include "kfd/algorithms/view_keyframe_selector.h"

namespace kfd {

void ViewKeyframeSelector::initialize(const Params& p) {
    guards_.initialize(p);
    view_.initialize(p.view);  // validates the view keys (their own field names)
    params_ = p;
    reset();
}

void ViewKeyframeSelector::reset() {
    guards_.reset();
    view_.reset();
}

KeyframeDecision ViewKeyframeSelector::filter(const Scan& scan) {
    const ViewMeasure m = view_.measure(scan);
    KeyframeDecision d;
    d.references = view_.hasKeyframe() ? 1 : 0;
    d.view_change = m.view_change;
    d.changed_fraction = m.changed_fraction;
    d.degeneracy = m.degeneracy;
    d.corridor = m.corridor;
    d.keyframe = m.keyframe;
    if (!view_.hasKeyframe())
        d.reason = KeyframeReason::First;
    else if (m.keyframe)
        d.reason = m.corridor ? KeyframeReason::Corridor : KeyframeReason::ViewChange;
    else {
        d.reason = KeyframeReason::Covered;
        guards_.apply(d, scan.timestamp, scan.odometry);
    }
    if (d.keyframe) view_.accept(scan);
    guards_.record(d, scan.timestamp, scan.odometry);
    return d;
}

}  // namespace kfd
