// A real rawlog with labelled noise injected (RealNoiseInjector), for scoring denoisers on real
// scans: every other return stays the sensor's own.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <string>

#include "kfd/sim/real_noise.h"

namespace kfd {

struct NoisyLogOptions {
    std::string input;   // a real rawlog (any layout, plain or gzip)
    std::string output;  // the noisy rawlog; its labels go to OUTPUT_STEM.labels.csv
    RealNoiseInjector::Params noise;
    unsigned seed = 1;
    /// Called every progress_every log entries and at the end: the fraction of the input read
    /// and the 2D scans read so far.
    std::function<void(double fraction, std::size_t scans)> on_progress;
    std::size_t progress_every = 500;
};

struct NoisyLogSummary {
    std::string rawlog, labels;
    std::size_t scans = 0, beams = 0;      // 2D scans, their valid beams before injection
    std::array<std::size_t, 4> by_kind{};  // labelled beams, by NoiseKind
    std::array<std::size_t, kNoiseModels> by_model{};  // labelled beams, by NoiseModel
};

/// Copies every object of `input` in order, adding labelled outliers to each 2D scan, and
/// writes the labels ("scan,timestamp,beam,kind,model": the scan's index among the log's 2D
/// scans, as kfd-denoise-eval counts them). Scans that fail kfd::checkScan are copied
/// unchanged. Outputs are checked against the input first (PathError) and written under
/// temporary names through kfd's checked writers, renamed when both are complete and checked.
/// SimulationError (or a SourceError) on bad input; WriteError ("cannot write noisy.rawlog: No
/// space left on device") when an output cannot be written.
NoisyLogSummary writeNoisyLog(const NoisyLogOptions& o);

}  // namespace kfd
