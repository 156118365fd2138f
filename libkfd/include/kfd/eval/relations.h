// The relations metric of Kümmerle et al. 2009 ("On measuring the accuracy of SLAM algorithms").
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "kfd/eval/trajectory.h"

namespace kfd {

/// One ground-truth relation: the pose at t2 in the frame of the pose at t1.
struct Relation {
    double t1 = 0.0, t2 = 0.0;
    Pose2D delta;
};

/// Reads a `.relations` file: lines "t1 t2 x y z roll pitch yaw" (z, roll, pitch ignored).
std::vector<Relation> readRelations(const std::string& path);

struct RelationsError {
    std::size_t used = 0;       // relations whose both stamps matched a pose
    std::size_t unmatched = 0;  // relations with a stamp farther than max_dt from any pose
    double trans_mean = 0, trans_std = 0;      // m
    double rot_mean_deg = 0, rot_std_deg = 0;  // deg
    double trans2_mean = 0, trans2_std = 0;    // m^2
    double rot2_mean = 0, rot2_std = 0;        // deg^2
};

/// For each relation, the estimated motion d_est = between(p(t1), p(t2)) is compared with the
/// ground truth component-wise, as the benchmark's evaluator does: the translation error is
/// |(d_est.x - d_gt.x, d_est.y - d_gt.y)| and the rotation error |wrap(d_est.phi - d_gt.phi)|.
/// Means and (population) standard deviations of the absolute and squared errors. Stamps are
/// matched to the nearest pose within max_dt; relations that do not match are counted, never
/// silently dropped. `traj` must be sorted by time. Throws EvalError when `relations` is empty,
/// when none matched (never a perfect 0.0), or when max_dt is negative or not finite (field
/// "max_dt").
RelationsError evaluateRelations(const Trajectory& traj, const std::vector<Relation>& relations,
                                 double max_dt);

/// Relations split by their time span: `local` when both stamps are at most split_s apart
/// (|t2 - t1| <= split_s), `far` otherwise. Local relations measure scan matching over a short
/// stretch (where a pre-filter's effect shows); long ones carry the drift of a SLAM without
/// loop closure. Order is kept. EvalError (field "split_s") when split_s is negative or not
/// finite.
struct RelationsByLength {
    std::vector<Relation> local, far;
};
RelationsByLength splitRelations(const std::vector<Relation>& relations, double split_s);

}  // namespace kfd
