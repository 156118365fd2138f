#include "slam_evaluation.h"

#include <optional>

#include "kfd/eval/ate.h"

namespace kfd::icp_slam {

void evaluateTrajectory(const IcpSlamOptions& opts, const std::vector<Relation>& relations,
                        const Trajectory& trajectory, const Trajectory& ground_truth,
                        IcpSlamSummary& sum) {
    if (opts.ground_truth_tum.empty() && relations.empty()) return;
    Trajectory sorted = trajectory;
    sortByTime(sorted);
    if (!opts.ground_truth_tum.empty())
        sum.ate_rmse = computeAte(sorted, ground_truth, opts.relations_max_dt).rmse;
    if (relations.empty()) return;
    // EvalError when no relation matched (never a perfect 0.0)
    sum.relations = evaluateRelations(sorted, relations, opts.relations_max_dt);
    sum.relations_file = opts.relations;
    // Local and long relations; a subset that is empty or matched nothing stays absent.
    const RelationsByLength split = splitRelations(relations, opts.split_seconds);
    sum.relations_local_count = split.local.size();
    sum.relations_long_count = split.far.size();
    auto subset = [&](const std::vector<Relation>& r) -> std::optional<RelationsError> {
        if (r.empty()) return std::nullopt;
        try {
            return evaluateRelations(sorted, r, opts.relations_max_dt);
        } catch (const EvalError&) {
            return std::nullopt;  // none of this subset matched
        }
    };
    sum.relations_local = subset(split.local);
    sum.relations_long = subset(split.far);
}

}  // namespace kfd::icp_slam
