#include "kfd/sim/real_noise.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace kfd {

const char* toString(NoiseModel m) {
    switch (m) {
        case NoiseModel::None:
            return "none";
        case NoiseModel::SpikeUniform:
            return "spike_uniform";
        case NoiseModel::SpikeNearSensor:
            return "spike_near_sensor";
        case NoiseModel::SpikeNearSurface:
            return "spike_near_surface";
        case NoiseModel::ClusterNearSensor:
            return "cluster_near_sensor";
        case NoiseModel::ClusterMidRange:
            return "cluster_mid_range";
        case NoiseModel::ClusterBeforeWall:
            return "cluster_before_wall";
        case NoiseModel::EdgeUniform:
            return "edge_uniform";
        case NoiseModel::EdgeNearFront:
            return "edge_near_front";
        case NoiseModel::EdgeNearBack:
            return "edge_near_back";
    }
    return "unknown";
}

NoiseModel parseNoiseModel(const std::string& s) {
    for (std::size_t m = 1; m < kNoiseModels; ++m)
        if (s == toString(static_cast<NoiseModel>(m))) return static_cast<NoiseModel>(m);
    throw ParameterError("model", "unknown model '" + s + "'");
}

NoiseKind kindOf(NoiseModel m) {
    const auto v = static_cast<int>(m);
    if (v == 0) return NoiseKind::Clean;
    if (v <= 3) return NoiseKind::Isolated;
    if (v <= 6) return NoiseKind::Clustered;
    return NoiseKind::Edge;
}

void RealNoiseInjector::initialize(const Params& p) {
    auto prob = [](double v) { return v >= 0.0 && v <= 1.0; };
    if (!prob(p.isolated_rate) || !prob(p.edge_rate))
        throw ParameterError("rates", "noise rates must be probabilities in [0, 1]");
    if (!(p.cluster_rate >= 0.0 && p.cluster_rate <= 10.0))
        throw ParameterError("cluster_rate", "clusters per scan must be in [0, 10]");
    if (!(p.edge_jump_m > 0.0) || !(p.min_range >= 0.0) || !std::isfinite(p.edge_jump_m) ||
        !std::isfinite(p.min_range))
        throw ParameterError("geometry", "invalid noise geometry");
    if (static_cast<std::size_t>(p.only) >= kNoiseModels)
        throw ParameterError("only", "unknown noise model");
    params_ = p;
}

namespace {

// One scan's injection: the real returns before any outlier, what each beam became, and the
// draws in a fixed order (edges, bursts, spikes) from one generator.
struct Injection {
    const RealNoiseInjector::Params& params;
    Scan& scan;
    std::vector<NoiseKind>& kinds;
    std::vector<NoiseModel>& models;
    std::mt19937& rng;
    const std::vector<float> truth;  // the real returns, before any outlier
    const std::vector<std::uint8_t> had;
    std::uniform_real_distribution<double> u{0.0, 1.0};

    std::size_t size() const { return truth.size(); }
    bool enabled(NoiseKind k) const {
        return params.only == NoiseModel::None || kindOf(params.only) == k;
    }
    // One of a kind's three models (first = its first model), or the fixed one.
    NoiseModel pick(NoiseModel first) {
        if (params.only != NoiseModel::None) return params.only;
        return static_cast<NoiseModel>(static_cast<int>(first) + static_cast<int>(u(rng) * 3.0));
    }
    void set(std::size_t j, double r, NoiseModel m) {
        scan.range[j] = static_cast<float>(r);
        scan.valid[j] = 1;
        kinds[j] = kindOf(m);
        models[j] = m;
    }
};

// Mixed pixels at depth edges of the real scan.
void injectEdges(Injection& in) {
    const std::size_t n = in.size();
    const auto& truth = in.truth;
    const auto& had = in.had;
    auto& u = in.u;
    auto& rng = in.rng;
    for (std::size_t i = 0; i + 1 < n; ++i) {
        if (!had[i] || !had[i + 1]) continue;
        const double a = truth[i], b = truth[i + 1];
        if (std::abs(a - b) <= in.params.edge_jump_m || u(rng) >= in.params.edge_rate) continue;
        const NoiseModel m = in.pick(NoiseModel::EdgeUniform);
        const double near = std::min(a, b), far = std::max(a, b);
        const double f = m == NoiseModel::EdgeNearFront  ? 0.05 + 0.25 * u(rng)
                         : m == NoiseModel::EdgeNearBack ? 0.7 + 0.25 * u(rng)
                                                         : 0.1 + 0.8 * u(rng);
        const bool veil = u(rng) < 0.5;  // the far surface's beams, else the near one's
        const bool left_is_far = a > b;
        // the side's beams, walking away from the edge: i, i-1, ... or i+1, i+2, ...
        const bool left = veil == left_is_far;
        const int count = 1 + static_cast<int>(u(rng) * 3.0);
        for (int k = 0; k < count; ++k) {
            const std::size_t j = left ? i - std::min<std::size_t>(i, k) : i + 1 + k;
            if (j >= n || !had[j] || in.kinds[j] != NoiseKind::Clean) break;
            const double surface = veil ? far : near;  // the side's own range
            if (std::abs(truth[j] - surface) > in.params.edge_jump_m) break;  // left the side
            in.set(j, near + f * (far - near) * (1.0 + 0.02 * (u(rng) - 0.5)), m);
            if (left && j == 0) break;
        }
        i += 3;  // no chain of edges through the beams just changed
    }
}

// Clustered outliers: a Poisson number of bursts per scan.
void injectBursts(Injection& in) {
    const std::size_t n = in.size();
    const auto& truth = in.truth;
    const auto& had = in.had;
    auto& u = in.u;
    auto& rng = in.rng;
    const double lo_r = in.params.min_range;
    std::poisson_distribution<int> count(in.params.cluster_rate);
    std::normal_distribution<double> jitter(0.0, 0.02);
    for (int c = count(rng); c > 0; --c) {
        const NoiseModel m = in.pick(NoiseModel::ClusterNearSensor);
        const std::size_t size = u(rng) < 0.5 ? 3 + static_cast<std::size_t>(u(rng) * 4.0)
                                              : 7 + static_cast<std::size_t>(u(rng) * 14.0);
        const std::size_t len = std::min(n, size);
        const std::size_t s = static_cast<std::size_t>(u(rng) * static_cast<double>(n - len + 1));
        const double centre =
            m == NoiseModel::ClusterNearSensor ? 0.2 + 1.3 * u(rng) : 1.5 + 2.5 * u(rng);
        const double slope = 0.6 * (u(rng) - 0.5);
        const double offset = 0.1 + 0.5 * u(rng);
        for (std::size_t j = s; j < s + len && j < n; ++j) {
            if (in.kinds[j] != NoiseKind::Clean) continue;
            double r;
            if (m == NoiseModel::ClusterBeforeWall) {
                if (!had[j] || truth[j] - offset < lo_r + 0.1) continue;
                r = truth[j] - offset + jitter(rng);
            } else {
                const double t = len > 1 ? static_cast<double>(j - s) / (len - 1) : 0.0;
                r = centre + (m == NoiseModel::ClusterMidRange ? slope * t : 0.0) + jitter(rng);
                if (had[j] && truth[j] <= r + 0.05) continue;  // behind the real return
            }
            in.set(j, std::max(lo_r, r), m);
        }
    }
}

// Isolated spikes on the beams left clean (no-return beams included, as real spikes are).
void injectSpikes(Injection& in) {
    auto& u = in.u;
    auto& rng = in.rng;
    const double lo_r = in.params.min_range;
    std::exponential_distribution<double> near_sensor(1.0 / 0.5);
    for (std::size_t i = 0; i < in.size(); ++i) {
        if (in.kinds[i] != NoiseKind::Clean || u(rng) >= in.params.isolated_rate) continue;
        const double top = in.had[i] ? in.truth[i] : 10.0;
        const NoiseModel m = in.pick(NoiseModel::SpikeUniform);
        double r;
        if (m == NoiseModel::SpikeNearSurface) {
            if (!in.had[i] || top < lo_r + 0.7) continue;
            r = top - (0.1 + 0.4 * u(rng));
        } else if (m == NoiseModel::SpikeNearSensor) {
            r = lo_r + near_sensor(rng);
            if (r >= top - 0.1) continue;
        } else {
            if (top <= lo_r + 0.2) continue;
            r = lo_r + (top - 0.1 - lo_r) * u(rng);
        }
        in.set(i, r, m);
    }
}

}  // namespace

void RealNoiseInjector::apply(Scan& scan, std::vector<NoiseKind>& kinds,
                              std::vector<NoiseModel>& models, std::mt19937& rng) const {
    const std::size_t n = scan.range.size();
    kinds.assign(n, NoiseKind::Clean);
    models.assign(n, NoiseModel::None);
    if (n == 0) return;
    Injection in{params_, scan, kinds, models, rng, scan.range, scan.valid};
    if (in.enabled(NoiseKind::Edge)) injectEdges(in);
    if (in.enabled(NoiseKind::Clustered)) injectBursts(in);
    if (in.enabled(NoiseKind::Isolated)) injectSpikes(in);
}

}  // namespace kfd
