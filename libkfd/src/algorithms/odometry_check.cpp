#include "kfd/algorithms/odometry_check.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include "kfd/algorithms/pose.h"

namespace kfd {

const char* toString(OdometryVerdict v) {
    switch (v) {
        case OdometryVerdict::None:
            return "none";
        case OdometryVerdict::Ok:
            return "ok";
        case OdometryVerdict::Frozen:
            return "frozen";
        case OdometryVerdict::Jump:
            return "jump";
    }
    return "none";
}

void OdometryCheck::initialize(const Params& p) {
    if (p.max_samples < 8 || p.max_samples > kMaxScanBeams)
        throw ParameterError("max_samples", "max_samples must be in [8, 65536]");
    auto nonneg = [](double v) { return v >= 0.0 && std::isfinite(v); };
    if (!nonneg(p.tolerance_m) || !nonneg(p.tolerance_ratio))
        throw ParameterError("odometry_tolerance", "the change tolerance must be finite and >= 0");
    if (!nonneg(p.still_m) || !nonneg(p.still_deg))
        throw ParameterError("odometry_still", "still_m and still_deg must be finite and >= 0");
    if (!(p.frozen_changed_fraction > 0.0 && p.frozen_changed_fraction < 1.0))
        throw ParameterError("frozen_changed_fraction",
                             "frozen_changed_fraction must be in (0, 1)");
    if (!(p.jump_margin > 0.0 && p.jump_margin < 1.0))
        throw ParameterError("jump_margin", "jump_margin must be in (0, 1)");
    if (p.min_beams < 1) throw ParameterError("min_beams", "min_beams must be >= 1");
    if (!(p.jump_pace_factor >= 1.0) || !std::isfinite(p.jump_pace_factor) || p.pace_steps < 3)
        throw ParameterError("jump_pace_factor", "jump_pace_factor must be >= 1, pace_steps >= 3");
    params_ = p;
    still_rad_ = p.still_deg * kPi / 180.0;
    reset();
}

void OdometryCheck::reset() {
    have_prev_ = have_anchor_ = frozen_ = false;
    prev_raw_.reset();
    correction_ = Pose2D{};
    pace_m_.clear();
    pace_rad_.clear();
}

// Whether `step` (over dt s; dt <= 0: per step) is far beyond the recent pace of the moving
// robot; records it in the pace unless it is a jump or a turn in place (no translation).
bool OdometryCheck::beyondPace(const Pose2D& step, double dt) {
    const double per = dt > 0.0 && std::isfinite(dt) ? 1.0 / dt : 1.0;
    const double m = std::hypot(step.x, step.y) * per, rad = std::fabs(step.phi) * per;
    auto median = [&](const std::vector<double>& v) {
        sorted_ = v;
        std::nth_element(sorted_.begin(), sorted_.begin() + std::ptrdiff_t(sorted_.size() / 2),
                         sorted_.end());
        return sorted_[sorted_.size() / 2];
    };
    bool beyond = false;
    if (pace_m_.size() >= params_.pace_steps / 2) {
        const double k = params_.jump_pace_factor;
        beyond = m > k * median(pace_m_) + params_.tolerance_m * per ||
                 rad > k * median(pace_rad_) + kPi / 180.0 * per;  // + 1 degree
    }
    if (std::hypot(step.x, step.y) < params_.still_m) return beyond;  // a turn in place
    if (!beyond) {  // a jump does not set the pace
        if (pace_m_.size() == params_.pace_steps) {
            pace_m_.erase(pace_m_.begin());
            pace_rad_.erase(pace_rad_.begin());
        }
        pace_m_.push_back(m);
        pace_rad_.push_back(rad);
    }
    return beyond;
}

void OdometryCheck::sample(const Scan& scan, Samples& out) const {
    out.geometry = scan.geometry;
    out.geometry.beams = scan.size();
    out.sensor = scan.sensor_pose;
    const std::size_t n = scan.size();
    const std::size_t k =
        std::max<std::size_t>(1, (n + params_.max_samples - 1) / params_.max_samples);
    out.range.clear();
    for (std::size_t i = 0; i < n; i += k)
        out.range.push_back(scan.valid[i] ? scan.range[i]
                                          : std::numeric_limits<float>::quiet_NaN());
}

double OdometryCheck::changedFraction(const Samples& a, const Samples& b, std::size_t& both) const {
    both = 0;
    if (a.geometry != b.geometry || a.range.size() != b.range.size()) return 0.0;
    std::size_t changed = 0;
    for (std::size_t j = 0; j < a.range.size(); ++j) {
        const float ra = a.range[j], rb = b.range[j];
        if (!(ra > 0.0f) || !(rb > 0.0f)) continue;  // NaN: no return in one of them
        ++both;
        const double tol = params_.tolerance_m + params_.tolerance_ratio * std::min(ra, rb);
        changed += std::fabs(double(ra) - double(rb)) > tol;
    }
    return both ? static_cast<double>(changed) / static_cast<double>(both) : 0.0;
}

double OdometryCheck::agreement(const Samples& from, const Scan& to, const Pose2D& step,
                                std::size_t& seen) const {
    seen = 0;
    const std::size_t n = to.size();
    const std::size_t stride =
        from.range.empty() ? 1 : (from.geometry.beams + from.range.size() - 1) / from.range.size();
    // previous sensor frame -> this sensor frame: inverse(S) (+) inverse(step) (+) S
    const Pose2D m = compose(compose(inverse(to.sensor_pose), inverse(step)), from.sensor);
    const double c = std::cos(m.phi), s = std::sin(m.phi);
    const double first = to.geometry.angle(0), dstep = to.geometry.step();
    if (dstep == 0.0) return 0.0;
    std::size_t agree = 0;
    for (std::size_t j = 0; j < from.range.size(); ++j) {
        const float r = from.range[j];
        if (!(r > 0.0f)) continue;
        ++seen;  // every previous return counts: one moved out of view disagrees
        const double a = from.geometry.angle(j * stride);
        const double px = r * std::cos(a), py = r * std::sin(a);
        const double qx = m.x + c * px - s * py, qy = m.y + s * px + c * py;
        double rel = wrapAngle(std::atan2(qy, qx) - first);
        if (dstep > 0.0 && rel < 0.0) rel += 2.0 * kPi;
        if (dstep < 0.0 && rel > 0.0) rel -= 2.0 * kPi;
        // The surface between the two beams bracketing q: a point falls between beams, and on
        // a wall seen at a grazing angle the nearest beam's range is far from its own.
        const double f = rel / dstep;
        if (!(f > -1.0 && f < static_cast<double>(n))) continue;
        const double fl = std::floor(f);
        const auto i0 = static_cast<std::ptrdiff_t>(fl);
        const double q = std::hypot(qx, qy);
        double best = std::numeric_limits<double>::infinity();
        double ax = 0, ay = 0;
        bool have_a = false;
        for (const std::ptrdiff_t i : {i0, i0 + 1}) {
            if (i < 0 || i >= static_cast<std::ptrdiff_t>(n) || !to.valid[std::size_t(i)]) continue;
            const double ri = to.range[std::size_t(i)], ai = to.geometry.angle(std::size_t(i));
            const double bx = ri * std::cos(ai), by = ri * std::sin(ai);
            best = std::min(best, std::hypot(qx - bx, qy - by));
            if (have_a) {  // both valid: the segment between them
                const double ex = bx - ax, ey = by - ay, len2 = ex * ex + ey * ey;
                if (len2 > 0.0) {
                    const double t = std::clamp(((qx - ax) * ex + (qy - ay) * ey) / len2, 0.0, 1.0);
                    best = std::min(best, std::hypot(qx - ax - t * ex, qy - ay - t * ey));
                }
            }
            ax = bx;
            ay = by;
            have_a = true;
        }
        agree += best <= params_.tolerance_m + params_.tolerance_ratio * q;
    }
    return seen ? static_cast<double>(agree) / static_cast<double>(seen) : 0.0;
}

OdometryCheck::Result OdometryCheck::check(Scan& scan) {
    Result res;
    sample(scan, cur_);
    const bool same_geometry = have_prev_ && prev_.geometry == cur_.geometry;
    if (!scan.odometry) {  // nothing to check; the next odometry starts afresh
        prev_raw_.reset();
        have_anchor_ = frozen_ = false;
    } else if (!prev_raw_ || !same_geometry) {  // the first scan with odometry
        res.verdict = OdometryVerdict::Ok;
        prev_raw_ = scan.odometry;
        anchor_ = cur_;
        have_anchor_ = true;
        frozen_ = false;
        scan.odometry = compose(correction_, *scan.odometry);
    } else {
        const Pose2D raw = *scan.odometry;
        const Pose2D step = between(*prev_raw_, raw);
        const bool still =
            std::hypot(step.x, step.y) < params_.still_m && std::fabs(step.phi) < still_rad_;
        res.verdict = OdometryVerdict::Ok;
        if (still) {
            if (!have_anchor_) {
                anchor_ = cur_;
                have_anchor_ = true;
            }
            std::size_t both = 0;
            res.changed_fraction = changedFraction(anchor_, cur_, both);
            if (both >= params_.min_beams && res.changed_fraction > params_.frozen_changed_fraction)
                frozen_ = true;
            if (frozen_) res.verdict = OdometryVerdict::Frozen;
        } else if (beyondPace(step,
                              std::isfinite(scan.timestamp) ? scan.timestamp - prev_stamp_ : 0.0)) {
            have_anchor_ = frozen_ = false;
            std::size_t seen_still = 0, seen_step = 0;
            res.agree_still = agreement(prev_, scan, Pose2D{}, seen_still);
            res.agree_odometry = agreement(prev_, scan, step, seen_step);
            if (seen_still >= params_.min_beams &&
                res.agree_still - res.agree_odometry > params_.jump_margin) {
                res.verdict = OdometryVerdict::Jump;
                // Rebased: the pose stays where the previous scan's was.
                correction_ = compose(compose(correction_, *prev_raw_), inverse(raw));
            }
        } else {
            have_anchor_ = frozen_ = false;
        }
        prev_raw_ = raw;
        if (res.verdict == OdometryVerdict::Ok)
            scan.odometry = compose(correction_, raw);
        else
            scan.odometry.reset();
    }
    std::swap(prev_, cur_);
    have_prev_ = true;
    prev_stamp_ = scan.timestamp;
    return res;
}

}  // namespace kfd
