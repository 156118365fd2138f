// Keyframe selection by the paper's rule (Sec. 3.1.4, Formula 3), plus the guards it lacks.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "kfd/algorithms/keyframe_guards.h"
#include "kfd/paper/histogram.h"
#include "kfd/paper/keyframe_window.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// The `keyframe` stage's algorithm (the `reference` and `paper-*` presets): a sliding window
/// of the m latest keyframe histograms, KeyframeWindow (kfd/paper/keyframe_window.h,
/// Formula 3), on the scan's histogram (kfd/paper/histogram.h, Sec. 3.1.2). kfd's guards
/// (KeyframeGuards, 0 = off) apply to the scans the rule drops.
class KeyframeSelector {
  public:
    struct Params : KeyframeGuards::Params {
        std::size_t bins = 20;   // n, histogram columns (Sec. 3.1.2)
        std::size_t window = 8;  // m, sliding-window size (Sec. 3.1.4, Formulas 4-5)
        double p_pair = 0.985;   // P_pair; P_threshold = P_pair^m (Formula 3)
    };

    KeyframeSelector() { initialize(Params{}); }
    explicit KeyframeSelector(const Params& p) { initialize(p); }

    /// Validates and applies parameters (kfd::ParameterError naming the field), then resets.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    /// Forgets every keyframe: the next scan is a keyframe (KeyframeReason::First).
    void reset();

    /// Decides on a histogram (size = bins) and updates the window when it is a keyframe.
    KeyframeDecision decide(const std::vector<double>& histogram, double timestamp,
                            const std::optional<Pose2D>& odometry);

    /// Decides on the scan (builds its histogram, Sec. 3.1.2). Does not modify the scan.
    KeyframeDecision filter(const Scan& scan);

    std::size_t windowSize() const { return window_.size(); }
    const std::vector<double>& lastHistogram() const { return scratch_; }

  private:
    Params params_;
    Histogram histogram_;
    KeyframeWindow window_;        // the paper's Formula 3 (kfd/paper/keyframe_window.h)
    KeyframeGuards guards_;        // kfd's, beyond the paper
    std::vector<double> scratch_;  // the latest histogram
};

}  // namespace kfd
