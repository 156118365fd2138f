// Stamped 2D trajectories: TUM file I/O and lookup by timestamp (SE(2) helpers: algorithms/pose.h).
// std only.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "kfd/algorithms/pose.h"  // compose, inverse, between, wrapAngle
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// A file that cannot be read or parsed (path and line in the message).
class EvalError : public Error {
  public:
    using Error::Error;
};

struct StampedPose {
    double t = 0.0;  // s
    Pose2D pose;
};
using Trajectory = std::vector<StampedPose>;

/// TUM format: one "t x y z qx qy qz qw" line per pose ('#' comments allowed); the yaw is read
/// from the quaternion (any non-zero norm). Throws EvalError naming the file and line on
/// malformed input: missing, unparsable or non-finite numbers, a quaternion of norm 0.
Trajectory readTum(const std::string& path);
/// Writes `traj` as TUM lines through kfd's checked OutputFile (kfd/os/output_paths.h):
/// WriteError naming `name` (the file users know; `path` when empty) and the reason when any
/// write, the fsync or the close fails.
void writeTum(const std::string& path, const Trajectory& traj, const std::string& name = {});

/// Reads the data lines of a text file (blank lines and '#' comments skipped) as `n` numbers
/// each and calls `row(values)` for every one. `what` names the file kind in errors; a line with
/// fewer than n numbers, a token that is not a number ("1.5abc") or a non-finite value throws
/// EvalError naming path and line ("path:line: expected ..."); so does an EvalError thrown by
/// `row` (its message prefixed with "path:line: ").
void readNumericRows(const std::string& path, const std::string& what, std::size_t n,
                     const std::string& expected, const std::function<void(const double*)>& row);

/// Index of the pose whose stamp is nearest to t, if within max_dt (s). The trajectory must be
/// sorted by time (see sortByTime).
std::optional<std::size_t> nearest(const Trajectory& traj, double t, double max_dt);
void sortByTime(Trajectory& traj);

}  // namespace kfd
