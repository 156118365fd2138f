#include "kfd/algorithms/range_aware_clustering.h"

#include <algorithm>
#include <cmath>
#include "kfd/pipeline/error.h"

namespace kfd {

void RangeAwareClustering::initialize(const Params& p) {
    if (!(p.angle_gap_factor > 0.0) || !std::isfinite(p.angle_gap_factor))
        throw ParameterError("angle_gap_factor", "angle_gap_factor must be > 0");
    if (!(p.jump_lambda_deg > 0.0 && p.jump_lambda_deg < 90.0))
        throw ParameterError("jump_lambda_deg", "jump_lambda_deg must be in (0, 90)");
    if (!(p.jump_sigma_m >= 0.0) || !std::isfinite(p.jump_sigma_m))
        throw ParameterError("jump_sigma_m", "jump_sigma_m must be >= 0");
    params_ = p;
    sin_lambda_ = std::sin(p.jump_lambda_deg * kPi / 180.0);
    half_lambda_ = 0.5 * p.jump_lambda_deg * kPi / 180.0;
}

double RangeAwareClustering::jumpDistance(double ra, double rb, double dtheta) const {
    // The angle stops counting at lambda/2: over wider gaps (10 beams at 1 deg resolution) the
    // bound would otherwise reach min(ra, rb) and link objects at twice the depth.
    const double a = std::min(dtheta, half_lambda_);
    return std::min(ra, rb) * std::sin(a) / sin_lambda_ + 3.0 * params_.jump_sigma_m;
}

RangeAwareClustering::Result RangeAwareClustering::cluster(const Scan& scan, Clusters& out) {
    Result res;
    const ScanGeometry& g = scan.geometry;
    const std::size_t n = scan.range.size();
    ScanGeometry geom = g;
    geom.beams = n;  // tables follow the actual data length
    dirs_.update(geom);
    const double res_ang = g.resolution();
    const double theta = params_.angle_gap_factor * res_ang;
    res.theta_threshold = theta;
    const bool wraps = n > 1 && g.seamGap() <= theta + 1e-12;

    sets_.clear();
    provisional_.assign(n, -1);
    open_.clear();
    updateJumpFactors(theta, res_ang);
    for (std::size_t i = 0; i < n; ++i)
        if (scan.valid[i]) addBeam(scan, i, theta, res_ang, res);
    if (wraps) joinAcrossSeam(scan, theta, res);
    out.finalize(scan, provisional_, sets_);
    return res;
}

void RangeAwareClustering::updateJumpFactors(double theta, double res_ang) {
    // jumpDistance() = min(ra, rb) * jump_factor_[gap] + noise_, per beam gap (the angle test
    // keeps gaps within theta / resolution).
    const std::size_t max_gap =
        res_ang > 0 ? static_cast<std::size_t>(theta / res_ang + 1e-6) : std::size_t{0};
    jump_factor_.resize(max_gap + 1);
    for (std::size_t gap = 0; gap <= max_gap; ++gap)
        jump_factor_[gap] =
            jumpDistance(1.0, 1.0, static_cast<double>(gap) * res_ang) - 3.0 * params_.jump_sigma_m;
    noise_ = 3.0 * params_.jump_sigma_m;
}

void RangeAwareClustering::addBeam(const Scan& scan, std::size_t i, double theta, double res_ang,
                                   Result& res) {
    const float r = scan.range[i];
    const float x = r * dirs_.cos[i], y = r * dirs_.sin[i];
    // Close clusters whose last point is more than theta behind.
    open_.erase(std::remove_if(open_.begin(), open_.end(),
                               [&](const Open& o) {
                                   return static_cast<double>(i - o.beam) * res_ang > theta + 1e-12;
                               }),
                open_.end());
    // Which open clusters this point reaches (angle test done above, jump test here), and
    // the nearest of them. Squared distances; the angle factor comes from jump_factor_.
    int best = -1;
    double best_d2 = 0.0;
    reach_.assign(open_.size(), 0);
    for (std::size_t k = 0; k < open_.size(); ++k) {
        const Open& o = open_[k];
        const double dx = x - o.x, dy = y - o.y, d2 = dx * dx + dy * dy;
        const double jump = std::min<double>(r, o.r) * jump_factor_[i - o.beam] + noise_;
        if (d2 <= jump * jump) {
            reach_[k] = 1;
            if (best < 0 || d2 < best_d2) {
                best = static_cast<int>(k);
                best_d2 = d2;
            }
        } else {
            ++res.splits;
        }
    }
    if (best < 0) {
        const std::uint32_t id = sets_.add();
        provisional_[i] = static_cast<std::int32_t>(id);
        open_.push_back(Open{id, static_cast<std::uint32_t>(i), x, y, r});
        return;
    }
    // Join the nearest; clusters that this point also reaches become one.
    const std::uint32_t id = open_[best].id;
    for (std::size_t k = 0; k < open_.size(); ++k)
        if (reach_[k] && static_cast<int>(k) != best)
            res.merges += sets_.unite(id, open_[k].id) ? 1 : 0;
    ++res.links;
    provisional_[i] = static_cast<std::int32_t>(id);
    open_[best] = Open{id, static_cast<std::uint32_t>(i), x, y, r};
}

void RangeAwareClustering::joinAcrossSeam(const Scan& scan, double theta, Result& res) {
    // Clusters open at the end of the scan against the first beams.
    const std::size_t n = scan.range.size();
    const double res_ang = scan.geometry.resolution();
    for (const Open& o : open_) {
        for (std::size_t j = 0; j < n; ++j) {
            const double dtheta =
                (static_cast<double>(n - 1 - o.beam + j)) * res_ang + scan.geometry.seamGap();
            if (dtheta > theta + 1e-12) break;
            if (!scan.valid[j] || provisional_[j] < 0) continue;
            const float r = scan.range[j];
            const double d = std::hypot(r * dirs_.cos[j] - o.x, r * dirs_.sin[j] - o.y);
            if (d <= jumpDistance(r, o.r, std::max(dtheta, 0.0)))
                res.merges +=
                    sets_.unite(o.id, static_cast<std::uint32_t>(provisional_[j])) ? 1 : 0;
        }
    }
}

}  // namespace kfd
