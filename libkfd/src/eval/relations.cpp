#include "kfd/eval/relations.h"

#include <cmath>

namespace kfd {
namespace {

struct Stats {
    double sum = 0, sum2 = 0;
    std::size_t n = 0;
    void add(double v) {
        sum += v;
        sum2 += v * v;
        ++n;
    }
    double mean() const { return n ? sum / static_cast<double>(n) : 0.0; }
    double stddev() const {  // population, as numpy's default
        if (!n) return 0.0;
        const double m = mean();
        return std::sqrt(std::max(0.0, sum2 / static_cast<double>(n) - m * m));
    }
};

}  // namespace

std::vector<Relation> readRelations(const std::string& path) {
    std::vector<Relation> rel;
    // t1 t2 x y z roll pitch yaw (z, roll, pitch are 0 in 2D benchmarks)
    readNumericRows(path, "relations file", 8, "t1 t2 x y z roll pitch yaw", [&](const double* v) {
        rel.push_back(Relation{v[0], v[1], {v[2], v[3], v[7]}});
    });
    return rel;
}

RelationsError evaluateRelations(const Trajectory& traj, const std::vector<Relation>& relations,
                                 double max_dt) {
    if (!(max_dt >= 0.0) || !std::isfinite(max_dt))
        throw EvalError("max_dt must be finite and >= 0 (got " + std::to_string(max_dt) + " s)",
                        "max_dt");
    if (relations.empty()) throw EvalError("no relations to evaluate");
    RelationsError e;
    Stats t, r, t2, r2;
    for (const auto& rel : relations) {
        const auto i = nearest(traj, rel.t1, max_dt);
        const auto j = nearest(traj, rel.t2, max_dt);
        if (!i || !j) {
            ++e.unmatched;
            continue;
        }
        const Pose2D d = between(traj[*i].pose, traj[*j].pose);
        const double et = std::hypot(d.x - rel.delta.x, d.y - rel.delta.y);
        const double er = std::abs(wrapAngle(d.phi - rel.delta.phi)) * 180.0 / kPi;
        t.add(et);
        r.add(er);
        t2.add(et * et);
        r2.add(er * er);
    }
    e.used = t.n;
    if (e.used == 0)
        throw EvalError("no relation matched the trajectory: " + std::to_string(e.unmatched) +
                        " relations, none with both stamps within " + std::to_string(max_dt) +
                        " s of a pose (" + std::to_string(traj.size()) + " poses)");
    e.trans_mean = t.mean();
    e.trans_std = t.stddev();
    e.rot_mean_deg = r.mean();
    e.rot_std_deg = r.stddev();
    e.trans2_mean = t2.mean();
    e.trans2_std = t2.stddev();
    e.rot2_mean = r2.mean();
    e.rot2_std = r2.stddev();
    return e;
}

RelationsByLength splitRelations(const std::vector<Relation>& relations, double split_s) {
    if (!(split_s >= 0.0) || !std::isfinite(split_s))
        throw EvalError("split_s must be finite and >= 0 (got " + std::to_string(split_s) + " s)",
                        "split_s");
    RelationsByLength out;
    for (const auto& rel : relations)
        (std::abs(rel.t2 - rel.t1) <= split_s ? out.local : out.far).push_back(rel);
    return out;
}

}  // namespace kfd
