#include "kfd/baselines/statistical_outlier.h"

#include <cmath>
#include <limits>
#include <string>

#include "kfd/pipeline/error.h"

namespace kfd {

void StatisticalOutlierFilter::initialize(const Params& p) {
    if (p.k < 1 || p.k > kMaxSorNeighbours)
        throw ParameterError("k",
                             "sor_k must be in [1, " + std::to_string(kMaxSorNeighbours) + "]");
    if (!(p.std_mul >= 0.0) || !std::isfinite(p.std_mul))
        throw ParameterError("std_mul", "sor_std_mul must be finite and >= 0");
    params_ = p;
}

StatisticalOutlierFilter::Result StatisticalOutlierFilter::filter(Scan& scan) {
    Result res;
    const std::size_t n = scan.range.size();
    pts_.assign(scan);
    beam_mean_.assign(n, std::numeric_limits<double>::quiet_NaN());
    // A valid beam without a finite range has no position: infinitely far from everything.
    for (const auto b : pts_.nonfinite) scan.valid[b] = 0;
    res.points_removed = pts_.nonfinite.size();
    const std::size_t m = pts_.size();
    res.points_in = m + pts_.nonfinite.size();
    if (m < 2) return res;  // no statistics
    tree_.build(pts_.x.data(), pts_.y.data(), m);
    mean_.resize(m);
    const std::size_t want = params_.k >= m ? m : params_.k + 1;  // k + 1 without overflow
    double sum = 0.0;
    for (std::size_t p = 0; p < m; ++p) {
        // k + 1 nearest, p itself included. Skip p; if ties at distance 0 (duplicates of p)
        // pushed p out of the answer, the first k are p's k nearest others all the same.
        tree_.knn(pts_.x[p], pts_.y[p], want, knn_idx_, knn_d2_);
        double s = 0.0;
        std::size_t used = 0;
        bool skipped = false;
        for (std::size_t j = 0; j < knn_idx_.size() && used < params_.k; ++j) {
            if (!skipped && knn_idx_[j] == p) {
                skipped = true;
                continue;
            }
            s += std::sqrt(static_cast<double>(knn_d2_[j]));
            ++used;
        }
        mean_[p] = s / static_cast<double>(used);  // used >= 1 since m >= 2
        sum += mean_[p];
    }
    const double mu = sum / static_cast<double>(m);
    double sq = 0.0;
    for (std::size_t p = 0; p < m; ++p) sq += (mean_[p] - mu) * (mean_[p] - mu);
    const double sigma = std::sqrt(sq / static_cast<double>(m - 1));
    const double threshold = mu + params_.std_mul * sigma;
    for (std::size_t p = 0; p < m; ++p) {
        beam_mean_[pts_.beam[p]] = mean_[p];
        if (mean_[p] > threshold) {
            scan.valid[pts_.beam[p]] = 0;
            ++res.points_removed;
        }
    }
    res.mean_distance = mu;
    res.stddev_distance = sigma;
    res.threshold = threshold;
    return res;
}

}  // namespace kfd
