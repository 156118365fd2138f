// Removals that look like a surface (issues 37, 39): the longest straight run of returns a
// denoising stage removed from one scan, so that a summary can flag a keyframe that lost a piece
// of wall instead of noise; and the same test sparing such runs before a denoiser removes them.
// std only.
#pragma once

#include <cstddef>
#include <cstdint>

#include "kfd/pipeline/scan.h"

namespace kfd {

/// A run of removed returns: consecutive beams that were valid before a stage and invalid after
/// it (beams that were invalid already do not break the run; a beam the stage left valid does).
/// It looks like a surface when it holds at least min_beams returns, spans at least
/// min_length_m along its line, its points lie on a line (total least squares) within
/// max(tolerance_m, tolerance_ratio x their mean range) RMS, and no two neighbours are farther
/// apart than max_gap_beams beam spacings at their range (a surface, not a scatter of spikes
/// at similar ranges).
struct SurfaceRunParams {
    std::size_t min_beams = 5;       // returns (issue 39: "a run of >= 5 beams on a line")
    double min_length_m = 0.0;       // m, along the fitted line
    double tolerance_m = 0.02;       // m, RMS distance to the line (the floor: 2 sigma of SICK)
    double tolerance_ratio = 0.005;  // of the run's mean range (a Hokuyo's 1 % sigma at 2 m)
    double max_gap_beams = 4.0;      // neighbours at most this many beam spacings apart
};

struct SurfaceRun {
    std::size_t first = 0;  // first beam of the run
    std::size_t beams = 0;  // returns removed in it (0: no run looks like a surface)
    double length_m = 0.0;  // extent along the fitted line
    double rms_m = 0.0;     // RMS distance of its points to the line
};

/// The longest (by length_m) run of returns removed from `scan` (valid in `before`, one flag
/// per beam, invalid in `scan.valid`) that looks like a surface; beams = 0 when none does.
/// Time O(n); no allocation.
SurfaceRun longestRemovedSurface(const Scan& scan, const std::uint8_t* before,
                                 const SurfaceRunParams& p = {});

/// Spares what looks like a surface before it is removed: `remove` flags the valid returns a
/// denoiser is about to remove (one flag per beam); every run of them (as above: valid returns
/// with the flag, broken by a valid return without it) that looks like a surface has its flags
/// cleared. Returns the returns spared. Time O(n); no allocation.
std::size_t spareSurfaceRuns(const Scan& scan, std::uint8_t* remove,
                             const SurfaceRunParams& p = {});

}  // namespace kfd
