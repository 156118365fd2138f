// Labelled noise for simulated scans: the three outlier kinds the paper names (Sec. 1). std only.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// Per-beam label of a simulated scan.
enum class NoiseKind : std::uint8_t {
    Clean = 0,      // a true return (or an invalid beam)
    Isolated = 1,   // isolated outlier: a lone spurious return anywhere in front of the surface
    Clustered = 2,  // clustered outliers near the sensor (a burst of consecutive bogus returns)
    Edge = 3,       // outlier near a signal: mixed pixel / veiling between two surfaces at an edge
};
const char* toString(NoiseKind k);

/// Adds outliers to a clean scan and labels every beam.
class NoiseInjector {
  public:
    struct Params {
        double isolated_rate = 0.005;  // probability per valid beam
        double cluster_rate = 0.05;    // probability per scan of one cluster near the sensor
        std::size_t cluster_min_beams = 3, cluster_max_beams = 8;  // beams per cluster
        double cluster_max_range = 1.5;  // m, clusters lie in [0.2, this] m
        double edge_rate = 0.3;          // probability per depth edge of veiling points
        double edge_jump_m = 0.3;        // m, a range jump larger than this is an edge
        double min_range = 0.1;          // m, no outlier closer than this
    };

    NoiseInjector() = default;
    explicit NoiseInjector(const Params& p) { initialize(p); }
    void initialize(const Params& p);  // kfd::ParameterError on bad rates
    const Params& params() const { return params_; }

    /// Modifies `scan` ranges (and validity for new returns) and writes one label per beam.
    void apply(Scan& scan, std::vector<NoiseKind>& labels, std::mt19937& rng) const;

  private:
    Params params_;
};

}  // namespace kfd
