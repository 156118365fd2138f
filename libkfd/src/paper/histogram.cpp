#include "kfd/paper/histogram.h"

#include "kfd/pipeline/error.h"

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
    // Bin b holds the beams i with floor(i * n / beams) = b, i.e. i in [ceil(b * beams / n),
    // ceil((b + 1) * beams / n)): the same split as a division per beam, without one.
    std::size_t i = 0;
    for (std::size_t b = 0; b < n; ++b) {
        const std::size_t end = ((b + 1) * beams + n - 1) / n;
        double sum = 0.0;
        std::size_t count = 0;
        for (; i < end; ++i) {
            if (!scan.valid[i]) continue;
            sum += scan.range[i];
            ++count;
        }
        out[b] = sum;
        counts_[b] = count;
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
