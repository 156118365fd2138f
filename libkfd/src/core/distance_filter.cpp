#include "kfd/core/distance_filter.h"

#include <cmath>
#include "kfd/core/error.h"

namespace kfd {

void DistanceFilter::initialize(const Params& p) {
    if (!(p.min_range >= 0.0) || !std::isfinite(p.min_range))
        throw ParameterError("min_range", "min_range must be a finite value >= 0");
    if (!(p.max_range > p.min_range) || !std::isfinite(p.max_range))
        throw ParameterError("max_range", "max_range must be finite and greater than min_range");
    params_ = p;
}

DistanceFilter::Result DistanceFilter::filter(Scan& scan) const {
    Result res;
    const std::size_t n = scan.range.size();
    scan.valid.resize(n, 0);  // no-op when sizes already match
    for (std::size_t i = 0; i < n; ++i) {
        if (!scan.valid[i]) continue;
        ++res.valid_in;
        const float r = scan.range[i];
        if (!std::isfinite(r)) {
            scan.valid[i] = 0;
            ++res.removed_non_finite;
        } else if (r < params_.min_range || r > params_.max_range) {
            scan.valid[i] = 0;
            ++res.removed_out_of_range;
        }
    }
    res.valid_out = res.valid_in - res.removed_non_finite - res.removed_out_of_range;
    return res;
}

}  // namespace kfd
