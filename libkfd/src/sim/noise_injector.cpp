#include "kfd/sim/noise_injector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kfd {

const char* toString(NoiseKind k) {
    switch (k) {
        case NoiseKind::Clean:
            return "clean";
        case NoiseKind::Isolated:
            return "isolated";
        case NoiseKind::Clustered:
            return "clustered";
        case NoiseKind::Edge:
            return "edge";
    }
    return "unknown";
}

void NoiseInjector::initialize(const Params& p) {
    auto prob = [](double v) { return v >= 0.0 && v <= 1.0; };
    if (!prob(p.isolated_rate) || !prob(p.cluster_rate) || !prob(p.edge_rate))
        throw ParameterError("rates", "noise rates must be probabilities in [0, 1]");
    if (p.cluster_min_beams < 1 || p.cluster_max_beams < p.cluster_min_beams)
        throw ParameterError("cluster_beams", "cluster beam counts must satisfy 1 <= min <= max");
    if (!(p.cluster_max_range > 0.2) || !(p.edge_jump_m > 0.0) || !(p.min_range >= 0.0))
        throw ParameterError("geometry", "invalid noise geometry");
    params_ = p;
}

void NoiseInjector::apply(Scan& scan, std::vector<NoiseKind>& labels, std::mt19937& rng) const {
    const std::size_t n = scan.range.size();
    labels.assign(n, NoiseKind::Clean);
    std::uniform_real_distribution<double> u(0.0, 1.0);

    // Outliers near signals: at a depth edge, one or two beams of the far side return a range
    // between the two surfaces (mixed pixels / veiling).
    for (std::size_t i = 0; i + 1 < n; ++i) {
        if (!scan.valid[i] || !scan.valid[i + 1]) continue;
        const double a = scan.range[i], b = scan.range[i + 1];
        if (std::abs(a - b) <= params_.edge_jump_m || u(rng) >= params_.edge_rate) continue;
        const std::size_t far = a > b ? i : i + 1;
        const double lo = std::min(a, b), hi = std::max(a, b);
        const int count = u(rng) < 0.5 ? 1 : 2;
        for (int k = 0; k < count; ++k) {
            const std::size_t j = far == i ? i - std::min<std::size_t>(i, k) : far + k;
            if (j >= n || !scan.valid[j] || labels[j] != NoiseKind::Clean) continue;
            if (scan.range[j] < hi - 1e-6) continue;  // only beams of the far surface
            scan.range[j] = static_cast<float>(lo + (hi - lo) * (0.2 + 0.6 * u(rng)));
            labels[j] = NoiseKind::Edge;
        }
        ++i;  // do not chain edges through the beam just changed
    }

    // Isolated outliers: a spurious return somewhere in front of the true surface.
    for (std::size_t i = 0; i < n; ++i) {
        if (labels[i] != NoiseKind::Clean || u(rng) >= params_.isolated_rate) continue;
        const double top = scan.valid[i] ? scan.range[i] : 10.0;
        if (top <= params_.min_range + 0.05) continue;
        scan.range[i] = static_cast<float>(params_.min_range + (top - params_.min_range) * u(rng));
        scan.valid[i] = 1;
        labels[i] = NoiseKind::Isolated;
    }

    // Clustered outliers near the sensor: a burst of consecutive bogus returns.
    if (n > 0 && u(rng) < params_.cluster_rate) {
        std::uniform_int_distribution<std::size_t> len(params_.cluster_min_beams,
                                                       params_.cluster_max_beams);
        const std::size_t m = std::min(n, len(rng));
        std::uniform_int_distribution<std::size_t> start(0, n - m);
        const std::size_t s = start(rng);
        const double centre = 0.2 + (params_.cluster_max_range - 0.2) * u(rng);
        for (std::size_t j = s; j < s + m; ++j) {
            const double r = centre + 0.05 * (u(rng) - 0.5);
            if (scan.valid[j] && scan.range[j] <= r) continue;  // would not be seen
            scan.range[j] = static_cast<float>(r);
            scan.valid[j] = 1;
            labels[j] = NoiseKind::Clustered;
        }
    }
}

}  // namespace kfd
