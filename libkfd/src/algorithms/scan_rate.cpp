#include "kfd/algorithms/scan_rate.h"

#include <algorithm>
#include <cmath>

namespace kfd {

void ScanRateMeter::add(double t) {
    if (!std::isfinite(t)) return;
    if (stamps_ == 0) {
        min_ = max_ = t;
    } else if (t > last_) {
        intervals_.push_back(static_cast<float>(t - last_));
    }
    min_ = std::min(min_, t);
    max_ = std::max(max_, t);
    last_ = t;
    ++stamps_;
}

ScanRate ScanRateMeter::result() const {
    ScanRate r;
    r.stamps = stamps_;
    r.span_s = max_ - min_;
    if (stamps_ > 1 && r.span_s > 0.0) r.mean_hz = static_cast<double>(stamps_ - 1) / r.span_s;
    if (!intervals_.empty()) {
        std::vector<float> v = intervals_;
        const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
        std::nth_element(v.begin(), mid, v.end());
        double m = *mid;
        if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), mid));
        r.median_interval_s = m;
    }
    return r;
}

}  // namespace kfd
