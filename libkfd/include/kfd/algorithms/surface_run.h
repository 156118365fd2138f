// Removals that look like a surface (issue 37): the longest straight run of returns a denoising
// stage removed from one scan, so that a summary can flag a keyframe that lost a piece of wall
// instead of noise. std only.
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
    std::size_t min_beams = 8;      // returns
    double min_length_m = 0.5;      // m, along the fitted line
    double tolerance_m = 0.02;      // m, RMS distance to the line (the floor)
    double tolerance_ratio = 0.01;  // of the run's mean range
    double max_gap_beams = 4.0;     // neighbours at most this many beam spacings apart
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

}  // namespace kfd
