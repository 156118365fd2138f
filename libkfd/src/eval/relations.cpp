#include "kfd/eval/relations.h"

#include <cmath>
#include <fstream>
#include <sstream>

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
    std::ifstream f(path);
    if (!f) throw EvalError("cannot open relations file " + path);
    std::vector<Relation> rel;
    std::string line;
    std::size_t lineno = 0;
    while (std::getline(f, line)) {
        ++lineno;
        const auto b = line.find_first_not_of(" \t\r");
        if (b == std::string::npos || line[b] == '#') continue;
        std::istringstream ss(line);
        Relation r;
        double z, roll, pitch;
        if (!(ss >> r.t1 >> r.t2 >> r.delta.x >> r.delta.y >> z >> roll >> pitch >> r.delta.phi))
            throw EvalError(path + ":" + std::to_string(lineno) +
                            ": expected 't1 t2 x y z roll pitch yaw'");
        rel.push_back(r);
    }
    return rel;
}

RelationsError evaluateRelations(const Trajectory& traj, const std::vector<Relation>& relations,
                                 double max_dt) {
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

}  // namespace kfd
