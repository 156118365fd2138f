// Labelled noise for REAL scans, independent of the simulator's noise model: several models per
// kind, drawn per event, so that no method can be fitted to one model. std only.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"
#include "kfd/sim/noise_injector.h"

namespace kfd {

/// Which model made a labelled beam (0 for clean beams). Each kind has three:
///  isolated spikes (one beam):
///   1 SpikeUniform     range uniform in [min_range, r) in front of the true return r
///   2 SpikeNearSensor  range exponential near the sensor (mean 0.5 m), as dust or a cable
///   3 SpikeNearSurface range just in front of the true return: r - U(0.1, 0.5) m
///  clustered outliers (a burst of consecutive beams, 3-6 or 7-20 beams, even odds):
///   4 ClusterNearSensor  flat, at 0.2-1.5 m (a person's leg, a hand on the sensor)
///   5 ClusterMidRange    slanted (a linear range ramp of up to +-0.3 m) at 1.5-4 m
///   6 ClusterBeforeWall  following the wall 0.1-0.6 m in front of it (glass, a reflection)
///  mixed pixels at a depth edge (|r_i - r_i+1| > edge_jump_m), 1-3 beams on one side:
///   7 EdgeUniform      interpolated at a fraction U(0.1, 0.9) of the gap
///   8 EdgeNearFront    at U(0.05, 0.3) of the gap from the near surface
///   9 EdgeNearBack     at U(0.7, 0.95) of the gap (close to the far surface)
///  the side is the far surface's beams (veiling) or the near surface's (blooming), even odds.
enum class NoiseModel : std::uint8_t {
    None = 0,
    SpikeUniform = 1,
    SpikeNearSensor = 2,
    SpikeNearSurface = 3,
    ClusterNearSensor = 4,
    ClusterMidRange = 5,
    ClusterBeforeWall = 6,
    EdgeUniform = 7,
    EdgeNearFront = 8,
    EdgeNearBack = 9,
};
inline constexpr std::size_t kNoiseModels = 10;
const char* toString(NoiseModel m);
/// The model named `s` (toString's names, None excluded); kfd::ParameterError (field "model",
/// detail "unknown model 's'") otherwise.
NoiseModel parseNoiseModel(const std::string& s);
/// The kind a model belongs to.
NoiseKind kindOf(NoiseModel m);

/// Adds labelled outliers to a real scan (whose returns are all taken as clean): per valid beam
/// an isolated spike with isolated_rate; per scan clusters with cluster_rate (a Poisson mean);
/// per depth edge mixed pixels with edge_rate. The model of each event is drawn uniformly
/// from the kind's three (or fixed by `only`).
class RealNoiseInjector {
  public:
    struct Params {
        double isolated_rate = 0.003;        // probability per valid beam
        double cluster_rate = 0.3;           // clusters per scan (Poisson mean)
        double edge_rate = 0.3;              // probability per depth edge
        double edge_jump_m = 0.3;            // m, a range jump larger than this is an edge
        double min_range = 0.1;              // m, no outlier closer than this
        NoiseModel only = NoiseModel::None;  // None: every model; else only this one (its kind)
    };

    RealNoiseInjector() = default;
    explicit RealNoiseInjector(const Params& p) { initialize(p); }
    /// kfd::ParameterError on rates outside [0, 1] (cluster_rate: [0, 10]) or a bad geometry.
    void initialize(const Params& p);
    const Params& params() const { return params_; }

    /// Modifies `scan` (ranges, and validity of beams that get a return) and writes one kind and
    /// one model per beam.
    void apply(Scan& scan, std::vector<NoiseKind>& kinds, std::vector<NoiseModel>& models,
               std::mt19937& rng) const;

  private:
    Params params_;
};

}  // namespace kfd
