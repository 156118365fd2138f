#include "kfd/eval/ground_truth.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "kfd/eval/trajectory.h"  // EvalError

namespace kfd {

const char* toString(GroundTruthFormat f) {
    switch (f) {
        case GroundTruthFormat::Tum:
            return "a TUM trajectory (t x y z qx qy qz qw)";
        case GroundTruthFormat::Relations:
            return "a relations file (t1 t2 x y z roll pitch yaw)";
        case GroundTruthFormat::Unknown:
            break;
    }
    return "neither clearly a TUM trajectory nor a relations file";
}

std::string GroundTruthGuess::evidence() const {
    std::ostringstream s;
    s << rows << " rows: " << later_stamp << " with a later stamp in column 2, " << shared_stamp
      << " with another row's stamp there, " << zero_5_to_7 << " with columns 5-7 zero; "
      << zero_4_to_6 << " with columns 4-6 zero, " << unit_quat
      << " with a unit quaternion in columns 5-8";
    return s.str();
}

GroundTruthGuess detectGroundTruthFormat(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw EvalError("ground truth not found: " + path, path);
    std::ifstream f(path);
    if (!f) throw EvalError("cannot open the ground truth " + path, path);
    std::vector<std::array<double, 8>> rows;
    std::string line;
    while (rows.size() < GroundTruthGuess::kMaxRows && std::getline(f, line)) {
        const auto b = line.find_first_not_of(" \t\r");
        if (b == std::string::npos || line[b] == '#') continue;
        std::istringstream ss(line);
        std::array<double, 8> v{};
        bool ok = true;
        for (auto& x : v) ok = ok && (ss >> x) && std::isfinite(x);
        if (ok) rows.push_back(v);
    }
    GroundTruthGuess g;
    g.rows = rows.size();
    if (rows.empty()) return g;
    std::vector<double> first;
    first.reserve(rows.size());
    for (const auto& v : rows) first.push_back(v[0]);
    std::sort(first.begin(), first.end());
    for (const auto& v : rows) {
        g.later_stamp += v[1] > v[0];
        const auto it = std::lower_bound(first.begin(), first.end(), v[1] - 1e-6);
        g.shared_stamp += it != first.end() && *it <= v[1] + 1e-6;
        g.zero_5_to_7 += v[4] == 0.0 && v[5] == 0.0 && v[6] == 0.0;
        g.zero_4_to_6 += v[3] == 0.0 && v[4] == 0.0 && v[5] == 0.0;
        const double n = std::sqrt(v[4] * v[4] + v[5] * v[5] + v[6] * v[6] + v[7] * v[7]);
        g.unit_quat += std::abs(n - 1.0) <= 1e-3;
    }
    const auto most = [&](std::size_t n) { return 10 * n >= 9 * g.rows; };  // >= 90 %
    const bool relations = most(g.zero_5_to_7) && (most(g.later_stamp) || most(g.shared_stamp));
    const bool tum = most(g.zero_4_to_6) || most(g.unit_quat);
    if (relations != tum)
        g.format = relations ? GroundTruthFormat::Relations : GroundTruthFormat::Tum;
    // Both fit. Unit quaternions in 90 % of the rows are TUM's (a yaw of +-1 rad in 90 % of the
    // relations is no benchmark's); else column 2 holding later stamps that are other rows'
    // stamps is a chain of relations (straight-line relations have y, z, roll, pitch 0 like a
    // planar TUM file; a hand-made TUM x may equal a stamp, but not always a later one).
    else if (relations && most(g.unit_quat))
        g.format = GroundTruthFormat::Tum;
    else if (relations && most(g.shared_stamp) && most(g.later_stamp))
        g.format = GroundTruthFormat::Relations;
    return g;
}

}  // namespace kfd
