#include "kfd/algorithms/keyframe_guards.h"

#include <cmath>

#include "kfd/algorithms/pose.h"
#include "kfd/pipeline/error.h"

namespace kfd {

const char* toString(KeyframeReason r) {
    switch (r) {
        case KeyframeReason::First:
            return "first";
        case KeyframeReason::Dissimilar:
            return "dissimilar";
        case KeyframeReason::MaxDrops:
            return "max_drops";
        case KeyframeReason::MaxInterval:
            return "max_interval";
        case KeyframeReason::Translation:
            return "translation";
        case KeyframeReason::Rotation:
            return "rotation";
        case KeyframeReason::Similar:
            return "similar";
        case KeyframeReason::ViewChange:
            return "view_change";
        case KeyframeReason::Corridor:
            return "corridor";
        case KeyframeReason::Covered:
            return "covered";
        case KeyframeReason::TrackPoor:
            return "track_poor";
        case KeyframeReason::TrackOdometry:
            return "track_odometry";
    }
    return "unknown";
}

namespace {

const char* describe(KeyframeReason r) {
    switch (r) {
        case KeyframeReason::First:
            return "kept: the sensor's first scan";
        case KeyframeReason::Dissimilar:
            return "kept by the paper's rule: its histogram correlates below P_pair^m with the "
                   "last m keyframes (Formula 3)";
        case KeyframeReason::Similar:
            return "dropped by the paper's rule: its histogram correlates with the last m "
                   "keyframes (Formula 3)";
        case KeyframeReason::ViewChange:
            return "kept: the view moved beyond the last keyframe's (max_view_change)";
        case KeyframeReason::Covered:
            return "dropped: the view has not moved beyond the last keyframe's, which still "
                   "covers it (the view selector)";
        case KeyframeReason::MaxDrops:
            return "kept by a guard: max_consecutive_drops scans dropped in a row";
        case KeyframeReason::MaxInterval:
            return "kept by a guard: max_interval_s since the last keyframe";
        case KeyframeReason::Translation:
            return "kept by a guard: max_translation_m of odometry since the last keyframe";
        case KeyframeReason::Rotation:
            return "kept by a guard: max_rotation_deg of odometry since the last keyframe";
        case KeyframeReason::Corridor:
            return "kept: a degenerate view (corridor), where the selector switches to odometry "
                   "or time";
        case KeyframeReason::TrackPoor:
            return "kept: the scan tracker could not align it to the last keyframe";
        case KeyframeReason::TrackOdometry:
            return "kept: its tracked motion and the odometry disagree (max_track_disagreement)";
    }
    return nullptr;
}

}  // namespace

const char* describeKeyframeReason(std::string_view name) {
    // Every reason by its toString() name: one list of names, the enum's.
    for (int i = 0; i <= static_cast<int>(KeyframeReason::TrackOdometry); ++i) {
        const auto r = static_cast<KeyframeReason>(i);
        if (name == toString(r)) return describe(r);
    }
    return nullptr;
}

void KeyframeGuards::initialize(const Params& p) {
    if (!(p.max_interval_s >= 0.0))
        throw ParameterError("max_interval_s", "max_interval_s must be >= 0 (0 = off)");
    if (!(p.max_translation_m >= 0.0))
        throw ParameterError("max_translation_m", "max_translation_m must be >= 0 (0 = off)");
    if (!(p.max_rotation_deg >= 0.0))
        throw ParameterError("max_rotation_deg", "max_rotation_deg must be >= 0 (0 = off)");
    params_ = p;
    reset();
}

void KeyframeGuards::reset() {
    drops_ = 0;
    have_stamp_ = false;
    last_odometry_.reset();
}

void KeyframeGuards::apply(KeyframeDecision& d, double timestamp,
                           const std::optional<Pose2D>& odometry) const {
    const double dt = timestamp - last_stamp_;
    if (params_.max_consecutive_drops > 0 && drops_ + 1 > params_.max_consecutive_drops) {
        d.keyframe = true;
        d.reason = KeyframeReason::MaxDrops;
    } else if (params_.max_interval_s > 0.0 && have_stamp_ && std::isfinite(timestamp) &&
               dt >= params_.max_interval_s) {
        d.keyframe = true;
        d.reason = KeyframeReason::MaxInterval;
    } else if (odometry && last_odometry_) {
        const Travel t = travel(*last_odometry_, *odometry);
        if (params_.max_translation_m > 0.0 && t.metres >= params_.max_translation_m) {
            d.keyframe = true;
            d.reason = KeyframeReason::Translation;
        } else if (params_.max_rotation_deg > 0.0 && t.degrees >= params_.max_rotation_deg) {
            d.keyframe = true;
            d.reason = KeyframeReason::Rotation;
        }
    }
}

void KeyframeGuards::record(KeyframeDecision& d, double timestamp,
                            const std::optional<Pose2D>& odometry) {
    if (d.keyframe) {
        drops_ = 0;
        if (std::isfinite(timestamp)) {
            last_stamp_ = timestamp;
            have_stamp_ = true;
        }
        if (odometry) last_odometry_ = odometry;
    } else {
        ++drops_;
    }
    d.consecutive_drops = drops_;
}

}  // namespace kfd
