// The paper's keyframe test: a sliding window of keyframe histograms, Sec. 3.1.4, Formula 3
// (std only). kfd's selector (kfd/algorithms/keyframe_selector.h) adds its guards around it.
#pragma once

#include <cstddef>
#include <vector>

#include "kfd/pipeline/error.h"

namespace kfd {

/// For a target histogram h, P_common = prod_j max(0, pearson(h, K_j)) over the k <= m keyframe
/// histograms K_j in the window (Formula 3); the scan is similar (dropped) when
/// P_common >= P_pair^k and new information (a keyframe) otherwise. With k < m references the
/// threshold is P_pair^k, so a short window is not made artificially permissive. A keyframe's
/// histogram enters the window through accept(), evicting the oldest.
class KeyframeWindow {
  public:
    struct Params {
        std::size_t bins = 20;   // n, histogram columns (Sec. 3.1.2)
        std::size_t window = 8;  // m, keyframes compared (Sec. 3.1.4, Formulas 4-5)
        double p_pair = 0.985;   // P_pair; P_threshold = P_pair^m (Formula 3)
    };
    /// Formula 3 for one histogram against the window.
    struct Verdict {
        bool keyframe = true;         // P_common < P_threshold, or the window is empty
        double p_common = 0.0;        // product of clamped correlations (0 when empty)
        double p_threshold = 1.0;     // P_pair^k (1 when empty)
        double min_similarity = 0.0;  // the weakest pairwise similarity
        std::size_t references = 0;   // k
    };

    KeyframeWindow() { initialize(Params{}); }
    explicit KeyframeWindow(const Params& p) { initialize(p); }
    /// kfd::ParameterError naming the field (bins < 2, window < 1, p_pair outside (0, 1]).
    void initialize(const Params& p);
    const Params& params() const { return params_; }
    /// Empties the window.
    void reset();

    /// Compares h (params().bins values) with the window; changes nothing.
    Verdict compare(const double* h) const;
    /// h enters the window (a keyframe), evicting the oldest when full.
    void accept(const double* h);
    /// k: keyframes held (<= window).
    std::size_t size() const { return count_; }

  private:
    const double* slot(std::size_t i) const { return &window_[i * params_.bins]; }

    Params params_;
    std::vector<double> window_;  // window * bins, ring buffer of keyframe histograms
    std::size_t head_ = 0;        // next slot to overwrite
    std::size_t count_ = 0;
};

}  // namespace kfd
