// Absolute trajectory error after SE(2) alignment, and relative pose error.
#pragma once

#include <cstddef>

#include "kfd/eval/trajectory.h"

namespace kfd {

struct AteResult {
    std::size_t matched = 0;             // estimated poses with a ground-truth pose within max_dt
    std::size_t unmatched = 0;           // estimated poses without one
    double rmse = 0, mean = 0, max = 0;  // m, translation after alignment
    Pose2D alignment;                    // applied to the estimate: gt ~ alignment (+) est
};

/// Matches each estimated pose to the nearest ground-truth stamp (within max_dt), finds the
/// rigid SE(2) transform that best aligns the estimated positions to the ground truth in the
/// least-squares sense (closed form, Umeyama 1991 without scale), and reports the translation
/// errors. Throws EvalError when fewer than 2 poses match, when fewer than half of the
/// estimate's poses match (the message gives matched and unmatched counts and max_dt: such a
/// ground truth belongs to another log), or when max_dt is negative or not finite (field
/// "max_dt"). `gt` must be sorted by time.
AteResult computeAte(const Trajectory& est, const Trajectory& gt, double max_dt);

struct RpeResult {
    std::size_t pairs = 0;      // pose pairs compared
    std::size_t unmatched = 0;  // ground-truth poses without an estimate within max_dt
    double trans_rmse = 0;      // m
    double rot_rmse_deg = 0;    // deg
};

/// Relative pose error over a fixed time step: for each ground-truth pose i, the first pose j
/// with t_j >= t_i + delta_s; the estimate's motion between the matched stamps is compared with
/// the ground truth's (error = between(d_gt, d_est)). `est` must be sorted by time. Throws
/// EvalError when no pair matched (never a perfect 0), when delta_s is not finite and > 0
/// (field "delta_s") or max_dt not finite and >= 0 (field "max_dt").
RpeResult computeRpe(const Trajectory& est, const Trajectory& gt, double delta_s, double max_dt);

}  // namespace kfd
