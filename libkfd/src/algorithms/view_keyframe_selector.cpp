#include "kfd/algorithms/view_keyframe_selector.h"

#include "kfd/algorithms/pose.h"

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

namespace {

// The tracker's motion since the keyframe when it aligned the scan; otherwise the selector
// measures as without a tracker (odometry, or the changed returns).
std::optional<Pose2D> trackedMotion(const TrackResult* t) {
    if (!t || !t->tracked()) return std::nullopt;
    return t->offset;
}

}  // namespace

KeyframeDecision ViewKeyframeSelector::filter(const Scan& scan, const TrackResult* track) {
    const ViewMeasure m = view_.measure(scan, trackedMotion(track));
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
    else if (track && track->verdict == TrackVerdict::Poor) {
        d.keyframe = true;
        d.reason = KeyframeReason::TrackPoor;
    } else if (disagrees(scan, track)) {
        d.keyframe = true;
        d.reason = KeyframeReason::TrackOdometry;
    } else {
        d.reason = KeyframeReason::Covered;
        guards_.apply(d, scan.timestamp, scan.odometry);
    }
    if (d.keyframe) view_.accept(scan);
    guards_.record(d, scan.timestamp, scan.odometry);
    return d;
}

}  // namespace kfd

namespace kfd {

// The tracked motion since the keyframe and the odometry's differ by max_track_disagreement
// (the view change of the one relative to the other): the odometry misses a turn or a slip.
bool ViewKeyframeSelector::disagrees(const Scan& scan, const TrackResult* track) const {
    const double limit = params_.view.max_track_disagreement;
    if (!(limit > 0.0) || !track || !track->tracked()) return false;
    const auto odometry = view_.odometrySinceKeyframe(scan);
    if (!odometry) return false;
    return view_.viewChange(between(*odometry, track->offset), scan.sensor_pose) >= limit;
}

}  // namespace kfd
