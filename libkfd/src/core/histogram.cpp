#include "kfd/core/histogram.h"

#include "kfd/core/error.h"

namespace kfd {

void Histogram::initialize(const Params& p) {
    if (p.bins == 0) throw ParameterError("bins", "histogram bins must be >= 1");
    params_ = p;
}

std::size_t Histogram::compute(const Scan& scan, std::vector<double>& out) const {
    const std::size_t n = params_.bins;
    const std::size_t beams = scan.range.size();
    out.assign(n, 0.0);
    counts_.assign(n, 0);
    for (std::size_t i = 0; i < beams; ++i) {
        if (!scan.valid[i]) continue;
        const std::size_t b = (i * n) / beams;  // equal angular intervals
        out[b] += scan.range[i];
        ++counts_[b];
    }
    std::size_t filled = 0;
    for (std::size_t b = 0; b < n; ++b) {
        if (counts_[b] > 0) {
            out[b] /= static_cast<double>(counts_[b]);
            ++filled;
        }
    }
    return filled;
}

}  // namespace kfd
