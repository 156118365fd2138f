#include "kfd/algorithms/keyframe_selector.h"

#include "kfd/pipeline/error.h"

namespace kfd {

void KeyframeSelector::initialize(const Params& p) {
    window_.initialize(KeyframeWindow::Params{p.bins, p.window, p.p_pair});  // bins, window, p_pair
    guards_.initialize(p);
    params_ = p;
    histogram_.initialize(Histogram::Params{p.bins});
    scratch_.assign(p.bins, 0.0);
    reset();
}

void KeyframeSelector::reset() {
    window_.reset();
    guards_.reset();
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
        if (!d.keyframe) guards_.apply(d, timestamp, odometry);
    }
    if (d.keyframe) window_.accept(h.data());
    guards_.record(d, timestamp, odometry);
    return d;
}

KeyframeDecision KeyframeSelector::filter(const Scan& scan) {
    histogram_.compute(scan, scratch_);
    return decide(scratch_, scan.timestamp, scan.odometry);
}

}  // namespace kfd
