#include "kfd/algorithms/keyframe_selector.h"

#include <algorithm>
#include <cmath>
#include <string>
#include "kfd/pipeline/error.h"

#include "kfd/algorithms/pose.h"

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
    }
    return "unknown";
}

const char* toString(KeyframeRule r) { return r == KeyframeRule::Paper ? "paper" : "view"; }

KeyframeRule parseKeyframeRule(const std::string& s) {
    if (s == "paper") return KeyframeRule::Paper;
    if (s == "view") return KeyframeRule::View;
    throw ParameterError("selector", "unknown selector '" + s + "' (paper or view)");
}

void KeyframeSelector::initialize(const Params& p) {
    auto bad = [](const char* field, const std::string& what) {
        throw ParameterError(field, what);
    };
    window_.initialize(KeyframeWindow::Params{p.bins, p.window, p.p_pair});  // bins, window, p_pair
    if (!(p.max_interval_s >= 0.0)) bad("max_interval_s", "max_interval_s must be >= 0 (0 = off)");
    if (!(p.max_translation_m >= 0.0))
        bad("max_translation_m", "max_translation_m must be >= 0 (0 = off)");
    if (!(p.max_rotation_deg >= 0.0))
        bad("max_rotation_deg", "max_rotation_deg must be >= 0 (0 = off)");
    view_.initialize(p.view);  // validates the view keys (their own field names)
    params_ = p;
    histogram_.initialize(Histogram::Params{p.bins});
    scratch_.assign(p.bins, 0.0);
    reset();
}

void KeyframeSelector::reset() {
    window_.reset();
    drops_ = 0;
    have_stamp_ = false;
    last_odometry_.reset();
    view_.reset();
}

void KeyframeSelector::applyGuards(KeyframeDecision& d, double timestamp,
                                   const std::optional<Pose2D>& odometry) {
    // Guards, in order of precedence.
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

void KeyframeSelector::record(KeyframeDecision& d, double timestamp,
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

KeyframeDecision KeyframeSelector::decide(const std::vector<double>& h, double timestamp,
                                          const std::optional<Pose2D>& odometry) {
    if (h.size() != params_.bins)
        throw ParameterError("histogram", "histogram size does not match the configured bins");
    const KeyframeWindow::Verdict v = window_.compare(h.data());  // Formula 3
    KeyframeDecision d;
    d.references = v.references;
    d.keyframe = v.keyframe;
    d.p_common = v.p_common;
    d.p_threshold = v.p_threshold;
    d.min_similarity = v.min_similarity;
    if (v.references == 0)
        d.reason = KeyframeReason::First;
    else {
        d.reason = d.keyframe ? KeyframeReason::Dissimilar : KeyframeReason::Similar;
        if (!d.keyframe) applyGuards(d, timestamp, odometry);
    }
    if (d.keyframe) window_.accept(h.data());
    record(d, timestamp, odometry);
    return d;
}

KeyframeDecision KeyframeSelector::filter(const Scan& scan) {
    if (params_.selector == KeyframeRule::Paper) {
        histogram_.compute(scan, scratch_);
        return decide(scratch_, scan.timestamp, scan.odometry);
    }
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
        applyGuards(d, scan.timestamp, scan.odometry);
    }
    if (d.keyframe) view_.accept(scan);
    record(d, scan.timestamp, scan.odometry);
    return d;
}

}  // namespace kfd
