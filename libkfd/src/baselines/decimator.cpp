#include "kfd/baselines/decimator.h"

#include <cmath>

namespace kfd {

void Decimator::initialize(const Params& p) {
    if (!(p.keep_fraction > 0.0 && p.keep_fraction <= 1.0) || !std::isfinite(p.keep_fraction))
        throw ParameterError("keep_fraction", "decimate_keep must be in (0, 1]");
    params_ = p;
    reset();
}

bool Decimator::keep() {
    // 1e-9: a fraction like 0.3 adds up to 0.999999... after 10 scans in binary.
    const bool kept = acc_ >= 1.0 - 1e-9;
    if (kept) acc_ -= 1.0;
    acc_ += params_.keep_fraction;
    return kept;
}

}  // namespace kfd
