// Keyframe selection: Sec. 3.1.4, Formula 3, plus guards the paper lacks.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "kfd/algorithms/view_selector.h"
#include "kfd/paper/histogram.h"
#include "kfd/paper/keyframe_window.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Why a scan was kept or dropped.
enum class KeyframeReason : std::uint8_t {
    First,        // first scan of the stream (or after reset): always a keyframe
    Dissimilar,   // P_common < P_threshold (Formula 3): new information
    MaxDrops,     // guard: too many consecutive drops
    MaxInterval,  // guard: too long since the last keyframe
    Translation,  // guard: odometry moved too far since the last keyframe
    Rotation,     // guard: odometry turned too far since the last keyframe (rotation in place)
    Similar,      // P_common >= P_threshold: dropped
    ViewChange,   // view selector: the view moved beyond the keyframe's
    Corridor,     // view selector, degenerate scene: odometry (or time) since the keyframe
    Covered,      // view selector: the keyframe covers this view: dropped
};
const char* toString(KeyframeReason r);

/// Outcome of one keyframe decision, with diagnostics.
struct KeyframeDecision {
    bool keyframe = true;
    KeyframeReason reason = KeyframeReason::First;
    double p_common = 0.0;        // product of clamped correlations with the window (Formula 3)
    double p_threshold = 0.0;     // P_pair^k, k = references compared
    double min_similarity = 0.0;  // the weakest pairwise similarity in the window
    std::size_t references = 0;   // k: keyframes compared against (<= window)
    std::size_t consecutive_drops = 0;  // drops since the last keyframe, this one included
    // the view selector's measures (selector = view; 0 / 1 / false otherwise)
    double view_change = 0.0;       // RMS displacement since the keyframe, in tolerances
    double changed_fraction = 0.0;  // laser only: share of common returns that changed
    double degeneracy = 1.0;        // lambda_min / lambda_max of the normals' information
    bool corridor = false;          // degeneracy below the switch's ratio
};

/// Which rule decides novelty: the paper's histogram correlation (Formula 3) or kfd's view
/// change (view_selector.h). The guards apply to both.
enum class KeyframeRule : std::uint8_t { Paper, View };
const char* toString(KeyframeRule r);
/// "paper" or "view"; kfd::ParameterError (field "selector") otherwise.
KeyframeRule parseKeyframeRule(const std::string& s);

/// Keyframe selection. With selector = paper (the `reference` and `paper-*` presets): a sliding
/// window of the m latest keyframe histograms (Sec. 3.1.4), below. With selector = view (kfd's
/// default): ViewSelector decides whether the view moved beyond the last keyframe's, and the
/// histogram is not computed.
///
/// Paper rule: KeyframeWindow (kfd/paper/keyframe_window.h, Formula 3) on the scan's histogram
/// (kfd/paper/histogram.h, Sec. 3.1.2).
///
/// Guards (each 0 = off) force a keyframe even when the scan looks similar; the paper has none,
/// and without them a robot rotating in place in a symmetric room, standing still for minutes,
/// or driving down a featureless corridor would produce no keyframe at all.
class KeyframeSelector {
  public:
    struct Params {
        KeyframeRule selector = KeyframeRule::View;  // novelty rule; Paper = Formula 3
        std::size_t bins = 20;                       // n, histogram columns (Sec. 3.1.2)
        std::size_t window = 8;  // m, sliding-window size (Sec. 3.1.4, Formulas 4-5)
        double p_pair = 0.985;   // P_pair; P_threshold = P_pair^m (Formula 3)
        // Guards (beyond the paper). 0 disables a guard.
        std::size_t max_consecutive_drops = 40;  // K: force a keyframe after K drops in a row
        double max_interval_s = 2.0;             // T (s) since the last keyframe
        double max_translation_m = 0.5;          // D (m) of odometry travel since the last keyframe
        double max_rotation_deg = 15.0;          // A (deg) of odometry turn since the last keyframe
        ViewSelector::Params view;               // selector = view
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

    /// Decides on the scan (paper: builds its histogram, Sec. 3.1.2; view: ViewSelector).
    /// Does not modify the scan.
    KeyframeDecision filter(const Scan& scan);

    std::size_t windowSize() const { return window_.size(); }
    const std::vector<double>& lastHistogram() const { return scratch_; }

  private:
    void applyGuards(KeyframeDecision& d, double timestamp, const std::optional<Pose2D>& odometry);
    /// Updates the drop count and, for a keyframe, the reference stamp and odometry of the
    /// guards; sets d.consecutive_drops.
    void record(KeyframeDecision& d, double timestamp, const std::optional<Pose2D>& odometry);

    Params params_;
    Histogram histogram_;
    ViewSelector view_;
    KeyframeWindow window_;        // the paper's Formula 3 (kfd/paper/keyframe_window.h)
    std::vector<double> scratch_;  // the latest histogram
    std::size_t drops_ = 0;        // consecutive drops since the last keyframe
    double last_stamp_ = 0.0;
    bool have_stamp_ = false;
    std::optional<Pose2D> last_odometry_;
};

}  // namespace kfd
