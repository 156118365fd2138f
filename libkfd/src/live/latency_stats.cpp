#include "kfd/live/latency_stats.h"

#include <algorithm>
#include <cmath>

namespace kfd::live {

void LatencyStats::add(double us) {
    if (ring_.size() < window_)
        ring_.push_back(us);
    else
        ring_[next_] = us;
    next_ = (next_ + 1) % window_;
    ++count_;
    max_ = std::max(max_, us);
}

double LatencyStats::percentile(double p) const {
    if (ring_.empty()) return 0.0;
    std::vector<double> v = ring_;
    const double rank = std::ceil(std::clamp(p, 0.0, 100.0) / 100.0 * double(v.size()));
    const std::size_t k = rank < 1.0 ? 0 : static_cast<std::size_t>(rank) - 1;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
}

}  // namespace kfd::live
