#include "kfd/eval/trajectory.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "kfd/os/output_paths.h"
#include "kfd/pipeline/format.h"

namespace kfd {

void readNumericRows(const std::string& path, const std::string& what, std::size_t n,
                     const std::string& expected, const std::function<void(const double*)>& row) {
    std::ifstream f(path);
    if (!f) throw EvalError("cannot open " + what + " " + path);
    std::vector<double> v(n);
    std::string line;
    std::size_t lineno = 0;
    while (std::getline(f, line)) {
        ++lineno;
        const auto b = line.find_first_not_of(" \t\r");
        if (b == std::string::npos || line[b] == '#') continue;
        const std::string where = path + ":" + std::to_string(lineno);
        std::istringstream ss(line);
        for (auto& x : v) {
            // A number must end at a space or the line's end ("1.5abc" is not a number) and be
            // finite (libstdc++ does not read "nan"/"inf"; an out-of-range value fails too).
            if (!(ss >> x) || !std::isfinite(x) ||
                (ss.peek() != std::char_traits<char>::eof() && !std::isspace(ss.peek())))
                throw EvalError(where + ": expected '" + expected + "' (numbers)", where);
        }
        try {
            row(v.data());
        } catch (const EvalError& e) {  // a row the caller rejects: name the file and line
            throw EvalError(where + ": " + e.what(), where);
        }
    }
}

Trajectory readTum(const std::string& path) {
    Trajectory traj;
    readNumericRows(path, "trajectory", 8, "t x y z qx qy qz qw", [&](const double* v) {
        const double norm = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
        if (!(norm > 1e-9)) throw EvalError("the quaternion has norm 0");
        // The yaw formula below needs a unit quaternion.
        const double qx = v[4] / norm, qy = v[5] / norm, qz = v[6] / norm, qw = v[7] / norm;
        const double yaw = std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz));
        traj.push_back(StampedPose{v[0], Pose2D{v[1], v[2], yaw}});
    });
    return traj;
}

void writeTum(const std::string& path, const Trajectory& traj, const std::string& name) {
    OutputFile f(path, name.empty() ? path : name);
    f << "# timestamp x y z qx qy qz qw\n";
    for (const auto& p : traj)  // any coordinates: no fixed buffer (kfd::format)
        f << format("%.6f %.6f %.6f 0 0 0 %.9f %.9f\n", p.t, p.pose.x, p.pose.y,
                    std::sin(0.5 * p.pose.phi), std::cos(0.5 * p.pose.phi));
    f.close();
}

std::optional<std::size_t> nearest(const Trajectory& traj, double t, double max_dt) {
    if (traj.empty()) return std::nullopt;
    const auto it = std::lower_bound(traj.begin(), traj.end(), t,
                                     [](const StampedPose& p, double v) { return p.t < v; });
    std::size_t best = static_cast<std::size_t>(it - traj.begin());
    if (best == traj.size()) best = traj.size() - 1;
    if (best > 0 && std::abs(traj[best - 1].t - t) <= std::abs(traj[best].t - t)) --best;
    if (std::abs(traj[best].t - t) > max_dt) return std::nullopt;
    return best;
}

void sortByTime(Trajectory& traj) {
    std::stable_sort(traj.begin(), traj.end(),
                     [](const StampedPose& a, const StampedPose& b) { return a.t < b.t; });
}

}  // namespace kfd
