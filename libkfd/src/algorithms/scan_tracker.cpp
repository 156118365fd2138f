#include "kfd/algorithms/scan_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "kfd/algorithms/evidence_filter.h"
#include "kfd/algorithms/point_to_line.h"
#include "kfd/algorithms/pose.h"

namespace kfd {

namespace {

constexpr double kDeg = kPi / 180.0;
// Fewer pairs than this: no fit (three unknowns, and a margin for outliers).
constexpr std::size_t kMinPairs = 12;
// Converged: a step below these (m, rad) once the gate is at its floor.
constexpr double kStepM = 1e-4, kStepRad = 1e-4;
// Noise allowance of the one-surface test between neighbouring keyframe returns (m).
constexpr float kLinkSlackM = 0.05f;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
// A keyframe segment's line spans at least this (m), grown by at most kMaxGrow beams a side.
constexpr float kBaselineM = 0.2f;
constexpr std::size_t kMaxGrow = 8;

ScanGeometry geometryOf(const Scan& scan) {
    ScanGeometry g = scan.geometry;
    g.beams = scan.range.size();
    return g;
}

// lambda_min / lambda_max of the 2x2 translation block [a b; b c] of J^T J.
double translationConditioning(double a, double b, double c) {
    const double mean = 0.5 * (a + c), half = 0.5 * (a - c);
    const double h = std::sqrt(half * half + b * b);
    const double hi = mean + h;
    return hi > 0.0 ? std::max(0.0, mean - h) / hi : 0.0;
}

}  // namespace

const char* toString(TrackVerdict v) {
    switch (v) {
        case TrackVerdict::First:
            return "first";
        case TrackVerdict::Tracked:
            return "tracked";
        case TrackVerdict::Degenerate:
            return "degenerate";
        case TrackVerdict::Poor:
            return "poor";
    }
    return "unknown";
}

void ScanTracker::initialize(const Params& p) {
    auto bad = [](const char* field, const char* what) { throw ParameterError(field, what); };
    if (p.max_samples < kMinPairs || p.max_samples > 65536)
        bad("max_samples", "track_samples must be in [12, 65536]");
    if (p.max_iterations < 1 || p.max_iterations > 100)
        bad("max_iterations", "track_iterations must be in [1, 100]");
    if (!(p.gate_m > 0.0) || !(p.gate_m <= 10.0)) bad("gate_m", "track_gate_m must be in (0, 10]");
    if (!(p.min_gate_m > 0.0) || !(p.min_gate_m <= p.gate_m))
        bad("min_gate_m", "track_min_gate_m must be in (0, track_gate_m]");
    if (!(p.min_overlap >= 0.0 && p.min_overlap <= 1.0))
        bad("min_overlap", "track_min_overlap must be in [0, 1]");
    if (!(p.max_spread > 0.0 && p.max_spread <= 1.0))
        bad("max_spread", "track_max_spread must be in (0, 1]");
    if (!(p.min_conditioning >= 0.0 && p.min_conditioning <= 1.0))
        bad("min_conditioning", "track_min_conditioning must be in [0, 1]");
    if (!(p.link_incidence_deg > 0.0 && p.link_incidence_deg < 90.0))
        bad("link_incidence_deg", "track_link_incidence_deg must be in (0, 90)");
    params_ = p;
    sin_incidence_ = std::sin(p.link_incidence_deg * kDeg);
    reset();
}

void ScanTracker::reset() {
    have_keyframe_ = false;
    kf_odometry_.reset();
    kf_pose_ = kf_mount_ = last_offset_ = velocity_ = Pose2D{};
    last_ = TrackResult{};
    started_ = false;
}

Pose2D ScanTracker::prior(const Scan& scan, bool& from_odometry) const {
    from_odometry = scan.odometry && kf_odometry_;
    if (from_odometry) return between(*kf_odometry_, *scan.odometry);
    return compose(last_offset_, velocity_);
}

TrackResult ScanTracker::track(const Scan& scan) {
    candidate_.range.assign(scan.range.begin(), scan.range.end());
    candidate_.valid.assign(scan.valid.begin(), scan.valid.end());
    candidate_.geometry = scan.geometry;
    candidate_.odometry = scan.odometry;
    candidate_.sensor_pose = scan.sensor_pose;
    TrackResult r;
    if (!have_keyframe_ || kf_geometry_ != geometryOf(scan)) {
        // The track starts (at the odometry, or the origin) or goes on from the last keyframe
        // by the prior across a new geometry.
        bool from_odometry = false;
        r.prior = r.offset = started_ ? prior(scan, from_odometry) : Pose2D{};
        r.odometry_prior = from_odometry;
        r.pose = started_ ? compose(kf_pose_, r.offset) : scan.odometry.value_or(Pose2D{});
        last_ = r;
        return r;
    }
    r.prior = prior(scan, r.odometry_prior);
    // The prior as the scan's sensor frame in the keyframe's.
    const auto sensorFrame = [&](const Pose2D& robot) {
        return compose(inverse(kf_mount_), compose(robot, scan.sensor_pose));
    };
    Fit f = align(scan, sensorFrame(r.prior));
    r.verdict = verdictOf(f);
    // The prior may be what failed (odometry slipping or glitching in a fast turn; constant
    // velocity after a wrong step): when its fit is poor, the fit from the scans' own motion
    // (constant velocity when the prior was the odometry, then no motion since the last scan)
    // is taken if it passes the gates. The prior reported stays the first one.
    const Pose2D own[] = {compose(last_offset_, velocity_), last_offset_};
    for (std::size_t k = r.odometry_prior ? 0 : 1; k < 2 && r.verdict == TrackVerdict::Poor; ++k) {
        const Fit g = align(scan, sensorFrame(own[k]));
        if (verdictOf(g) != TrackVerdict::Tracked) continue;
        f = g;
        r.verdict = TrackVerdict::Tracked;
    }
    r.iterations = static_cast<std::uint16_t>(f.iterations);
    r.pairs = static_cast<std::uint16_t>(std::min<std::size_t>(f.pairs, 65535));
    r.overlap = overlapOf(f);
    r.rms_m = static_cast<float>(f.rms);
    r.conditioning = static_cast<float>(f.conditioning);
    // A degenerate fit keeps the odometry; without odometry the fit is still the better guess
    // (its damping leaves the unconstrained direction at the prior).
    const bool use_fit = r.verdict == TrackVerdict::Tracked ||
                         (r.verdict == TrackVerdict::Degenerate && !r.odometry_prior);
    r.offset = use_fit ? compose(kf_mount_, compose(f.d, inverse(scan.sensor_pose))) : r.prior;
    r.pose = compose(kf_pose_, r.offset);
    // Without odometry a scan that could not be aligned says nothing of the motion: constant
    // velocity stops there (else a wrong step would be extrapolated scan after scan).
    const bool blind = r.verdict == TrackVerdict::Poor && !r.odometry_prior;
    velocity_ = blind ? Pose2D{} : between(last_offset_, r.offset);
    last_offset_ = r.offset;
    last_ = r;
    return r;
}

float ScanTracker::overlapOf(const Fit& f) {
    return f.samples ? static_cast<float>(f.pairs) / static_cast<float>(f.samples) : 0.0f;
}

TrackVerdict ScanTracker::verdictOf(const Fit& f) const {
    const Params& p = params_;
    if (f.pairs < kMinPairs || overlapOf(f) < p.min_overlap || f.rms > p.max_spread * f.gate)
        return TrackVerdict::Poor;
    return f.conditioning < p.min_conditioning ? TrackVerdict::Degenerate : TrackVerdict::Tracked;
}

ScanTracker::Fit ScanTracker::align(const Scan& scan, const Pose2D& prior_sensor) {
    Fit f;
    f.d = prior_sensor;
    const std::size_t n = scan.range.size();
    // The sampled returns, once.
    dirs_.update(geometryOf(scan));
    const std::size_t stride =
        std::max<std::size_t>(1, (n + params_.max_samples - 1) / params_.max_samples);
    px_.clear();
    py_.clear();
    for (std::size_t i = 0; i < n; i += stride) {
        const float r = scan.range[i];
        if (!scan.valid[i] || !(r > 0.0f) || !std::isfinite(r)) continue;
        px_.push_back(r * dirs_.cos[i]);
        py_.push_back(r * dirs_.sin[i]);
    }
    f.samples = px_.size();
    if (f.samples < kMinPairs) return f;
    const float first = static_cast<float>(kf_geometry_.angle(0));
    const float inv_step = static_cast<float>(1.0 / kf_geometry_.step());
    const float last_u = static_cast<float>(n - 1);
    double gate = params_.gate_m;
    for (std::size_t it = 0; it < params_.max_iterations; ++it) {
        const float c = static_cast<float>(std::cos(f.d.phi)),
                    s = static_cast<float>(std::sin(f.d.phi));
        const float tx = static_cast<float>(f.d.x), ty = static_cast<float>(f.d.y);
        const float g = static_cast<float>(gate);
        PointToLineSystem<double> sys;
        double e2 = 0.0;
        for (std::size_t j = 0; j < f.samples; ++j) {
            const float qx = c * px_[j] - s * py_[j] + tx, qy = s * px_[j] + c * py_[j] + ty;
            const float u = (EvidenceFilter::approxAtan2(qy, qx) - first) * inv_step;
            if (!(u >= 0.0f) || !(u < last_u)) continue;
            const std::size_t k = static_cast<std::size_t>(u);
            if (!link_[k]) continue;
            const float e = nx_[k] * (qx - ax_[k]) + ny_[k] * (qy - ay_[k]);
            if (!(std::abs(e) <= g)) continue;
            sys.add(nx_[k], ny_[k], qx, qy, e);
            e2 += static_cast<double>(e) * e;
        }
        f.iterations = it + 1;
        f.pairs = sys.pairs;
        f.gate = gate;
        if (sys.pairs < kMinPairs) break;
        f.rms = std::sqrt(e2 / static_cast<double>(sys.pairs));
        f.conditioning = translationConditioning(sys.A[0], sys.A[1], sys.A[3]);
        const Pose2D before = f.d;
        if (!sys.step(f.d)) break;
        const bool small = std::hypot(f.d.x - before.x, f.d.y - before.y) < kStepM &&
                           std::abs(f.d.phi - before.phi) < kStepRad;
        if (gate > params_.min_gate_m)
            gate = std::max(params_.min_gate_m, 0.5 * gate);
        else if (small)
            break;
    }
    return f;
}

void ScanTracker::accept() {
    const Scan& scan = candidate_;
    if (scan.range.empty()) return;  // nothing tracked since the last reset
    const ScanGeometry g = geometryOf(scan);
    const std::size_t n = g.beams;
    dirs_.update(g);
    kx_.resize(n);
    ky_.resize(n);
    nx_.resize(n);
    ny_.resize(n);
    ax_.resize(n);
    ay_.resize(n);
    link_.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const float r = scan.range[i];
        const bool ok = scan.valid[i] && r > 0.0f && std::isfinite(r);
        kx_[i] = ok ? r * dirs_.cos[i] : kNaN;
        ky_[i] = ok ? r * dirs_.sin[i] : kNaN;
    }
    // One surface: the gap between two neighbouring returns is what a surface seen at an
    // incidence of at least link_incidence_deg leaves, plus the noise slack.
    const float res = static_cast<float>(g.resolution());
    const float sin_l = static_cast<float>(sin_incidence_);
    for (std::size_t k = 0; k + 1 < n; ++k) {
        const float dx = kx_[k + 1] - kx_[k], dy = ky_[k + 1] - ky_[k];
        const float gap = std::sqrt(dx * dx + dy * dy);  // NaN when either has no return
        const float r = std::min(scan.range[k], scan.range[k + 1]);
        link_[k] = (gap > 1e-6f) && (gap * sin_l <= r * res + kLinkSlackM * sin_l);
    }
    keyframeLines();
    have_keyframe_ = started_ = true;
    kf_geometry_ = g;
    kf_odometry_ = scan.odometry;
    kf_mount_ = scan.sensor_pose;
    kf_pose_ = last_.pose;
    last_offset_ = Pose2D{};
}

void ScanTracker::keyframeLines() {
    const std::size_t n = kx_.size();
    // Each linked segment's line: the chord of the surface around it, grown on both sides
    // while the surface goes on until it spans kBaselineM (neighbouring returns of a dense
    // scanner are closer than its noise), through the mean of the returns it spans.
    for (std::size_t k = 0; k + 1 < n; ++k) {
        if (!link_[k]) continue;
        std::size_t a = k, b = k + 1;
        auto span2 = [&] {
            const float dx = kx_[b] - kx_[a], dy = ky_[b] - ky_[a];
            return dx * dx + dy * dy;
        };
        for (std::size_t grow = 0; grow < kMaxGrow && span2() < kBaselineM * kBaselineM; ++grow) {
            const bool left = a > 0 && link_[a - 1], right = b + 1 < n && link_[b];
            if (!left && !right) break;
            if (left) --a;
            if (right) ++b;
        }
        const float dx = kx_[b] - kx_[a], dy = ky_[b] - ky_[a];
        const float len = std::sqrt(dx * dx + dy * dy);
        float mx = 0.0f, my = 0.0f;
        for (std::size_t i = a; i <= b; ++i) {
            mx += kx_[i];
            my += ky_[i];
        }
        const float inv = 1.0f / static_cast<float>(b - a + 1);
        nx_[k] = -dy / len;
        ny_[k] = dx / len;
        ax_[k] = mx * inv;
        ay_[k] = my * inv;
    }
}

}  // namespace kfd
