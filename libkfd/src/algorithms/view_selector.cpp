#include "kfd/algorithms/view_selector.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "kfd/algorithms/pose.h"

namespace kfd {

void ViewSelector::initialize(const Params& p) {
    auto bad = [](const char* field, const char* what) { throw ParameterError(field, what); };
    auto nonneg = [](double v) { return v >= 0.0 && std::isfinite(v); };
    if (p.max_samples < 2) bad("max_samples", "max_samples must be >= 2");
    if (!(p.tolerance_m > 0.0) || !std::isfinite(p.tolerance_m))
        bad("tolerance_m", "tolerance_m must be > 0 (m)");
    if (!(p.tolerance_deg >= 0.0 && p.tolerance_deg < 90.0))
        bad("tolerance_deg", "tolerance_deg must be in [0, 90) (deg)");
    if (!(p.max_view_change > 0.0) || !std::isfinite(p.max_view_change))
        bad("max_view_change", "max_view_change must be > 0");
    if (!nonneg(p.change_tolerance_m)) bad("change_tolerance_m", "change_tolerance_m must be >= 0");
    if (!nonneg(p.change_tolerance_ratio))
        bad("change_tolerance_ratio", "change_tolerance_ratio must be >= 0");
    if (!(p.max_changed_fraction > 0.0 && p.max_changed_fraction <= 1.0))
        bad("max_changed_fraction", "max_changed_fraction must be in (0, 1]");
    if (!(p.degeneracy_ratio >= 0.0 && p.degeneracy_ratio <= 1.0))
        bad("degeneracy_ratio", "degeneracy_ratio must be in [0, 1] (0 = off)");
    if (!(p.corridor_translation_m > 0.0) || !std::isfinite(p.corridor_translation_m))
        bad("corridor_translation_m", "corridor_translation_m must be > 0 (m)");
    if (!(p.corridor_rotation_deg > 0.0 && p.corridor_rotation_deg <= 360.0))
        bad("corridor_rotation_deg", "corridor_rotation_deg must be in (0, 360] (deg)");
    if (!(p.corridor_interval_s > 0.0) || !std::isfinite(p.corridor_interval_s))
        bad("corridor_interval_s", "corridor_interval_s must be > 0 (s)");
    if (!nonneg(p.max_track_disagreement))
        bad("max_track_disagreement", "max_track_disagreement must be >= 0 (0 = off)");
    params_ = p;
    tan_b_ = std::tan(p.tolerance_deg * kPi / 180.0);
    reset();
}

void ViewSelector::reset() {
    have_keyframe_ = false;
    kf_samples_.clear();
    kf_odometry_.reset();
    kf_have_stamp_ = false;
}

std::size_t ViewSelector::stride(std::size_t beams) const {
    return std::max<std::size_t>(1, (beams + params_.max_samples - 1) / params_.max_samples);
}

ViewMeasure ViewSelector::measure(const Scan& scan, const std::optional<Pose2D>& motion) {
    const std::size_t k = stride(scan.range.size());
    const std::size_t n = (scan.range.size() + k - 1) / k;
    dirs_.update(scan.geometry);
    const bool odometry = (motion || (scan.odometry && kf_odometry_)) && have_keyframe_;
    const bool compare =
        !odometry && have_keyframe_ && kf_geometry_ == scan.geometry && kf_samples_.size() == n;
    const Samples s = sample(scan, k, compare);

    ViewMeasure m;
    m.degeneracy = degeneracyOf(s);
    m.corridor = params_.degeneracy_ratio > 0.0 && m.degeneracy < params_.degeneracy_ratio;
    if (!have_keyframe_) return m;  // keyframe = true
    w_sum_ = s.w_sum;
    wx_ = s.wx;
    wy_ = s.wy;
    wq_ = s.wq;
    points_ = s.points;
    if (odometry)
        decideByOdometry(scan, motion, m);
    else
        decideByChange(scan, compare, s, m);
    return m;
}

ViewSelector::Samples ViewSelector::sample(const Scan& scan, std::size_t k, bool compare) const {
    const Params& p = params_;
    const float a = static_cast<float>(p.tolerance_m), b = static_cast<float>(tan_b_);
    const float ct = static_cast<float>(p.change_tolerance_m);
    const float cr = static_cast<float>(p.change_tolerance_ratio);
    // the largest gap between neighbouring samples that is still one surface: 0.3 m plus four
    // times the sample spacing at that range (incidence up to ~75 deg)
    const float spacing =
        static_cast<float>(4.0 * scan.geometry.resolution() * static_cast<double>(k));
    Samples s;
    float px = 0, py = 0;
    bool prev = false;
    const std::size_t beams = scan.range.size();
    const float* range = scan.range.data();
    const std::uint8_t* valid = scan.valid.data();
    const float* cosine = dirs_.cos.data();
    const float* sine = dirs_.sin.data();
    const float* kf = kf_samples_.data();
    for (std::size_t i = 0, j = 0; i < beams; i += k, ++j) {
        if (!valid[i]) {
            prev = false;
            continue;
        }
        const float r = range[i];
        const float x = r * cosine[i], y = r * sine[i];
        const float t = a + b * r;
        const float w = 1.0f / (t * t);
        ++s.points;
        s.w_sum += w;
        s.wx += w * x;
        s.wy += w * y;
        s.wq += w * r * r;
        if (prev) {
            const float dx = x - px, dy = y - py, d2 = dx * dx + dy * dy;
            const float gate = 0.3f + spacing * r;
            if (d2 > 0.0f && d2 <= gate * gate) {
                const float inv = 1.0f / d2;
                s.sxx += dx * dx * inv;
                s.sxy += dx * dy * inv;
                ++s.tangents;
            }
        }
        px = x;
        py = y;
        prev = true;
        if (compare) {
            const float kr = kf[j];
            if (kr == kr) {  // not NaN
                ++s.both;
                s.changed += std::abs(r - kr) > ct + cr * r;
            }
        }
    }
    return s;
}

double ViewSelector::degeneracyOf(const Samples& s) {
    // Corridor switch: eigenvalues of N = tangents * I - S (S the tangent scatter).
    if (s.tangents < 8) return 1.0;
    const double half = 0.5 * static_cast<double>(s.tangents);
    const double dxy = static_cast<double>(s.sxx) - half;  // (sxx - syy) / 2
    const double h = std::sqrt(dxy * dxy + static_cast<double>(s.sxy) * s.sxy);
    return std::max(0.0, half - h) / (half + h);
}

void ViewSelector::decideByOdometry(const Scan& scan, const std::optional<Pose2D>& motion,
                                    ViewMeasure& m) const {
    const Params& p = params_;
    m.used_odometry = true;
    const Pose2D rel = motion ? *motion : *odometrySinceKeyframe(scan);
    m.view_change = viewChange(rel, scan.sensor_pose);
    if (m.corridor) {
        const Travel t = travel(Pose2D{}, rel);
        m.keyframe = t.metres >= p.corridor_translation_m || t.degrees >= p.corridor_rotation_deg;
    } else
        m.keyframe = m.view_change >= p.max_view_change;
}

void ViewSelector::decideByChange(const Scan& scan, bool compare, const Samples& s,
                                  ViewMeasure& m) const {
    // Laser only: the per-beam change test (no common returns: the view is new).
    m.changed_fraction = (compare && s.both >= 3)
                             ? static_cast<double>(s.changed) / static_cast<double>(s.both)
                             : 1.0;
    if (m.corridor && kf_have_stamp_ && std::isfinite(scan.timestamp))
        m.keyframe = scan.timestamp - kf_stamp_ >= params_.corridor_interval_s;
    else
        m.keyframe = m.changed_fraction >= params_.max_changed_fraction;
}

double ViewSelector::viewChange(const Pose2D& rel, const Pose2D& s) const {
    // translation: every point moves |t|, against the range-free unit a
    const double a = params_.tolerance_m;
    double e2 = (rel.x * rel.x + rel.y * rel.y) / (a * a);
    if (points_ > 0) {
        // rotation: a point at range r moves 2 sin(phi / 2) r, against a + r tan b;
        // sum w |p'|^2 in the robot frame, p' = Rs p + ts
        const double cs = std::cos(s.phi), ss = std::sin(s.phi);
        const double q = wq_ + 2.0 * (s.x * (cs * wx_ - ss * wy_) + s.y * (ss * wx_ + cs * wy_)) +
                         w_sum_ * (s.x * s.x + s.y * s.y);
        e2 += 2.0 * (1.0 - std::cos(rel.phi)) * q / static_cast<double>(points_);
    }
    return std::sqrt(std::max(0.0, e2));
}

std::optional<Pose2D> ViewSelector::odometrySinceKeyframe(const Scan& scan) const {
    if (!have_keyframe_ || !scan.odometry || !kf_odometry_) return std::nullopt;
    return between(*kf_odometry_, *scan.odometry);
}

void ViewSelector::accept(const Scan& scan) {
    const std::size_t beams = scan.range.size();
    const std::size_t k = stride(beams);
    kf_samples_.resize((beams + k - 1) / k);
    for (std::size_t j = 0, i = 0; i < beams; ++j, i += k)
        kf_samples_[j] = scan.valid[i] ? scan.range[i] : std::numeric_limits<float>::quiet_NaN();
    have_keyframe_ = true;
    kf_geometry_ = scan.geometry;
    kf_odometry_ = scan.odometry;
    kf_have_stamp_ = std::isfinite(scan.timestamp);
    if (kf_have_stamp_) kf_stamp_ = scan.timestamp;
}

}  // namespace kfd
