// Denoising quality against per-beam noise labels (simulated logs from kfd-simulate).
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <string>

#include "kfd/pipeline/pipeline.h"
#include "kfd/sim/noise_injector.h"
#include "kfd/sim/real_noise.h"

namespace kfd {

struct DenoiseQuality {
    std::size_t scans = 0;   // scans in the log
    std::size_t scored = 0;  // scans kept by the pipeline: the only ones scored (what SLAM sees)
    std::size_t points = 0;  // valid beams on input
    std::size_t noise = 0, clean = 0;
    std::size_t removed_noise = 0;                 // true positives
    std::size_t removed_clean = 0;                 // false positives
    std::array<std::size_t, 4> noise_by_kind{};    // indexed by NoiseKind
    std::array<std::size_t, 4> removed_by_kind{};  // indexed by NoiseKind
    double microseconds = 0;                       // total time in the pipeline
    /// With a label file that names models (kfd-inject): labelled and removed beams by model.
    std::array<std::size_t, kNoiseModels> noise_by_model{}, removed_by_model{};
    /// Clean points and the clean points removed by range band, [0, 2), [2, 5), [5, 10) and
    /// [10, inf) m: where a method removes real returns.
    static constexpr std::array<double, 4> kBandStartM = {0.0, 2.0, 5.0, 10.0};
    std::array<std::size_t, 4> clean_by_band{}, removed_clean_by_band{};
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
    double recall(NoiseModel m) const {
        const auto i = static_cast<std::size_t>(m);
        return noise_by_model[i] ? static_cast<double>(removed_by_model[i]) / noise_by_model[i]
                                 : 0.0;
    }
    /// Share of the clean points of range band b that were removed.
    double cleanRemoved(std::size_t band) const {
        return clean_by_band[band]
                   ? static_cast<double>(removed_clean_by_band[band]) / clean_by_band[band]
                   : 0.0;
    }
    /// Fraction of true points kept.
    double cleanKept() const {
        return clean ? 1.0 - static_cast<double>(removed_clean) / clean : 1.0;
    }
};

/// Runs every scan of a labelled rawlog through `pipeline` (normally without the keyframe
/// stage, so every scan is denoised) and scores the removed beams against the labels CSV
/// written by kfd-simulate ("scan,timestamp,beam,kind") or kfd-inject (with a fifth column,
/// the model). A clean log scored against a label file with no rows gives the real points a
/// method removes. Only the scans the pipeline keeps are scored (a dropped scan's noise never
/// reaches the SLAM; a pipeline without a keyframe stage keeps, and scores, every scan). Throws
/// SimulationError on unreadable files or labels that do not fit the rawlog. With
/// `laser_only` the log's odometry is withheld from the pipeline (a LaserScan-only source).
DenoiseQuality evaluateDenoising(const std::string& rawlog, const std::string& labels_csv,
                                 const Pipeline::Params& pipeline, bool laser_only = false);

}  // namespace kfd
