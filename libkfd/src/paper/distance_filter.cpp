#include "kfd/paper/distance_filter.h"

#include <cmath>
#include <cstdint>
#include <limits>

#include "kfd/pipeline/error.h"

namespace kfd {

void DistanceFilter::initialize(const Params& p) {
    if (!(p.min_range >= 0.0) || !std::isfinite(p.min_range))
        throw ParameterError("min_range", "min_range must be a finite value >= 0");
    if (!(p.max_range > p.min_range))
        throw ParameterError("max_range",
                             "max_range must be greater than min_range (+inf: the scan's own)");
    params_ = p;
    // The float nearest each limit, moved one step inwards when rounding went outwards.
    lo_ = static_cast<float>(p.min_range);
    if (static_cast<double>(lo_) < p.min_range)
        lo_ = std::nextafter(lo_, std::numeric_limits<float>::infinity());
    // +inf (the scan's own maximum) becomes the largest float: r <= hi_ stays false for +inf.
    constexpr float kLargest = std::numeric_limits<float>::max();
    const bool above = p.max_range >= static_cast<double>(kLargest);  // +inf included
    hi_ = above ? kLargest : static_cast<float>(p.max_range);
    if (!above && static_cast<double>(hi_) > p.max_range)
        hi_ = std::nextafter(hi_, -std::numeric_limits<float>::infinity());
}

DistanceFilter::Result DistanceFilter::filter(Scan& scan) const {
    Result res;
    const std::size_t n = scan.range.size();
    scan.valid.resize(n, 0);  // no-op when sizes already match
    const float* range = scan.range.data();
    std::uint8_t* valid = scan.valid.data();
    const float lo = lo_;
    // The scan's own maximum, narrowed by the parameter (NaN or <= 0 from a source: unknown).
    const float hi = scan.max_range > 0.0f && scan.max_range < hi_ ? scan.max_range : hi_;
    res.max_range_used = hi == std::numeric_limits<float>::max()
                             ? std::numeric_limits<double>::infinity()
                             : static_cast<double>(hi);
    for (std::size_t i = 0; i < n; ++i) {
        if (!valid[i]) continue;
        ++res.valid_in;
        const float r = range[i];
        if (r >= lo && r <= hi) continue;  // false for NaN and +-inf
        valid[i] = 0;
        if (std::isfinite(r))
            ++res.removed_out_of_range;
        else
            ++res.removed_non_finite;
    }
    res.valid_out = res.valid_in - res.removed_non_finite - res.removed_out_of_range;
    return res;
}

}  // namespace kfd
