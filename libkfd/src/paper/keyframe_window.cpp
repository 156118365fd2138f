#include "kfd/paper/keyframe_window.h"

#include <algorithm>
#include <cmath>

#include "kfd/paper/correlation.h"

namespace kfd {

void KeyframeWindow::initialize(const Params& p) {
    if (p.bins < 2)
        throw ParameterError("bins",
                             "bins must be >= 2 (a correlation needs at least two columns)");
    if (p.window < 1) throw ParameterError("window", "window must be >= 1");
    if (!(p.p_pair > 0.0 && p.p_pair <= 1.0))
        throw ParameterError("p_pair", "p_pair must be in (0, 1]");
    params_ = p;
    window_.assign(p.window * p.bins, 0.0);
    reset();
}

void KeyframeWindow::reset() {
    head_ = 0;
    count_ = 0;
}

KeyframeWindow::Verdict KeyframeWindow::compare(const double* h) const {
    Verdict v;
    v.references = count_;
    if (count_ == 0) return v;
    // Formula 3: P_common = prod_j P(target, K_j), compared with P_pair^k.
    double p = 1.0, pmin = 1.0;
    for (std::size_t j = 0; j < count_; ++j) {
        const double s = similarity(h, slot(j), params_.bins);
        p *= s;
        pmin = std::min(pmin, s);
    }
    v.p_common = p;
    v.min_similarity = pmin;
    v.p_threshold = std::pow(params_.p_pair, static_cast<double>(count_));
    v.keyframe = p < v.p_threshold;
    return v;
}

void KeyframeWindow::accept(const double* h) {
    std::copy(h, h + params_.bins,
              window_.begin() + static_cast<std::ptrdiff_t>(head_ * params_.bins));
    head_ = (head_ + 1) % params_.window;
    count_ = std::min(count_ + 1, params_.window);
}

}  // namespace kfd
