// Denoising quality against per-beam noise labels (simulated logs from kfd-simulate).
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <string>

#include "kfd/core/pipeline.h"
#include "kfd/sim/noise_injector.h"

namespace kfd {

struct DenoiseQuality {
    std::size_t scans = 0;
    std::size_t points = 0;  // valid beams on input
    std::size_t noise = 0, clean = 0;
    std::size_t removed_noise = 0;                 // true positives
    std::size_t removed_clean = 0;                 // false positives
    std::array<std::size_t, 4> noise_by_kind{};    // indexed by NoiseKind
    std::array<std::size_t, 4> removed_by_kind{};  // indexed by NoiseKind
    double microseconds = 0;                       // total time in the pipeline
    double precision() const {
        const auto r = removed_noise + removed_clean;
        return r ? static_cast<double>(removed_noise) / r : 0.0;
    }
    double recall() const { return noise ? static_cast<double>(removed_noise) / noise : 0.0; }
    double f1() const {
        const double p = precision(), r = recall();
        return p + r > 0 ? 2 * p * r / (p + r) : 0.0;
    }
    double recall(NoiseKind k) const {
        const auto i = static_cast<std::size_t>(k);
        return noise_by_kind[i] ? static_cast<double>(removed_by_kind[i]) / noise_by_kind[i] : 0.0;
    }
    /// Fraction of true points kept.
    double cleanKept() const {
        return clean ? 1.0 - static_cast<double>(removed_clean) / clean : 1.0;
    }
};

/// Runs every scan of a simulated rawlog through `pipeline` (normally without the keyframe
/// stage, so every scan is denoised) and scores the removed beams against the labels CSV
/// written by kfd-simulate. A dropped scan counts as removing nothing. Throws
/// SimulationError on unreadable files or labels that do not fit the rawlog.
DenoiseQuality evaluateDenoising(const std::string& rawlog, const std::string& labels_csv,
                                 const Pipeline::Params& pipeline);

}  // namespace kfd
