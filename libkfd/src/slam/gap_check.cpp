#include "kfd/slam/gap_check.h"

#include <algorithm>

namespace kfd {

GapCheck::GapCheck(double config_minimum, Params p) : config_minimum_(config_minimum), p_(p) {
    ring_.reserve(p_.recent);
}

void GapCheck::accepted(double goodness) {
    if (p_.recent == 0) return;
    if (ring_.size() < p_.recent)
        ring_.push_back(goodness);
    else
        ring_[next_] = goodness;
    next_ = (next_ + 1) % p_.recent;
}

double GapCheck::minimum() const {
    if (ring_.empty() || ring_.size() < p_.min_recent) return config_minimum_;
    std::vector<double> g = ring_;
    const auto mid = g.begin() + static_cast<std::ptrdiff_t>(g.size() / 2);
    std::nth_element(g.begin(), mid, g.end());
    return std::max(config_minimum_, p_.median_share * *mid);
}

}  // namespace kfd
