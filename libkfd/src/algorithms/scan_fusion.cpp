#include "kfd/algorithms/scan_fusion.h"
#include "kfd/algorithms/point_to_line.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "kfd/algorithms/evidence_filter.h"
#include "kfd/algorithms/pose.h"

namespace kfd {

namespace {

constexpr double kDeg = kPi / 180.0;
// sqrt(1.5): a beam's residual against its two neighbours' line has variance 1.5 sigma^2.
constexpr double kResidualScale = 1.2247448713915889;
// The breakpoint's incidence limit (the evidence filter's default lambda).
constexpr double kLambda = 10.0 * kDeg;
// Agreeing differences a scan needs before its median bias can be checked.
constexpr std::size_t kMinPairs = 16;
constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

ScanFusion::Estimator parseFusionEstimator(const std::string& text) {
    if (text == "median") return ScanFusion::Estimator::Median;
    if (text == "mean") return ScanFusion::Estimator::Mean;
    throw ParameterError("fuse_estimator",
                         "fuse_estimator must be median or mean, not '" + text + "'");
}

const char* toString(ScanFusion::Estimator e) {
    return e == ScanFusion::Estimator::Mean ? "mean" : "median";
}

void ScanFusion::initialize(const Params& p) {
    if (p.max_scans < 1 || p.max_scans > 64)
        throw ParameterError("max_scans", "fuse_max_scans must be in [1, 64]");
    if (p.min_agreeing < 1 || p.min_agreeing > p.max_scans)
        throw ParameterError("min_agreeing", "fuse_min_agreeing must be in [1, fuse_max_scans]");
    if (!(p.gate_sigmas > 0.0) || !std::isfinite(p.gate_sigmas))
        throw ParameterError("gate_sigmas", "fuse_gate_sigmas must be > 0");
    if (!(p.max_bias_sigmas > 0.0) || !std::isfinite(p.max_bias_sigmas))
        throw ParameterError("max_bias_sigmas", "fuse_max_bias_sigmas must be > 0");
    if (!(p.min_sigma_m > 0.0) || !std::isfinite(p.min_sigma_m))
        throw ParameterError("min_sigma_m", "fuse_min_sigma_m must be > 0");
    if (!(p.max_step_m > 0.0) || !std::isfinite(p.max_step_m))
        throw ParameterError("max_step_m", "fuse_max_step_m must be > 0");
    if (!(p.max_step_deg > 0.0) || !(p.max_step_deg <= 180.0))
        throw ParameterError("max_step_deg", "fuse_max_step_deg must be in (0, 180]");
    if (p.max_span_beams < 1 || p.max_span_beams > 64)
        throw ParameterError("max_span_beams", "fuse_max_span_beams must be in [1, 64]");
    if (p.refine_iterations > 20)
        throw ParameterError("refine_iterations", "fuse_refine_iterations must be in [0, 20]");
    if (p.refine_samples < 12 || p.refine_samples > 4096)
        throw ParameterError("refine_samples", "fuse_refine_samples must be in [12, 4096]");
    if (!(p.refine_gate_m > 0.0) || !(p.refine_gate_m <= 10.0))
        throw ParameterError("refine_gate_m", "fuse_refine_gate_m must be in (0, 10]");
    params_ = p;
    slots_.assign(p.max_scans, Slot{});
    used_.assign(p.max_scans, 0);
    reset();
}

void ScanFusion::reset() {
    head_ = count_ = 0;
    sigma_smoothed_ = -1.0;
}

void ScanFusion::observe(const Scan& scan) {
    if (!scan.odometry) return;  // no common frame with the keyframe: laser only fuses nothing
    ScanGeometry g = scan.geometry;
    g.beams = scan.range.size();
    if (count_ > 0) {  // a new geometry: the kept scans no longer compare
        const std::size_t newest = (head_ + slots_.size() - 1) % slots_.size();
        if (slots_[newest].geometry != g) count_ = 0;
    }
    Slot& s = slots_[head_];
    s.range.assign(scan.range.begin(), scan.range.end());
    s.valid.assign(scan.valid.begin(), scan.valid.end());
    s.geometry = g;
    s.pose = compose(*scan.odometry, scan.sensor_pose);
    head_ = (head_ + 1) % slots_.size();
    count_ = std::min(count_ + 1, slots_.size());
}

double ScanFusion::measureSigma(const Scan& scan, std::size_t stride, std::vector<float>& scratch) {
    const std::size_t n = scan.range.size();
    ScanGeometry g = scan.geometry;
    g.beams = n;
    const double cos_res = std::cos(g.resolution());
    scratch.clear();
    for (std::size_t i = 1; i + 1 < n; i += stride) {
        if (!scan.valid[i - 1] || !scan.valid[i] || !scan.valid[i + 1]) continue;
        const double e = EvidenceFilter::lineResidual(scan.range[i - 1], scan.range[i],
                                                      scan.range[i + 1], cos_res);
        if (std::isfinite(e)) scratch.push_back(static_cast<float>(std::abs(e)));
    }
    if (scratch.size() < kMinPairs) return 0.0;
    auto q = scratch.begin() + static_cast<std::ptrdiff_t>(scratch.size() / 10);
    std::nth_element(scratch.begin(), q, scratch.end());
    return static_cast<double>(*q) / (0.1257 * kResidualScale);
}

bool ScanFusion::refine(const Scan& kf, const Slot& slot, Pose2D& d) const {
    // Projective point-to-line alignment (EvidenceFilter::refineStep's method): each sampled
    // return is projected into the keyframe and paired with the keyframe segment between its
    // two bracketing beams (when they are one surface); Gauss-Newton on the distances to those
    // lines corrects the step. The gate halves per iteration; too few pairs keep the step.
    const std::size_t n = kf.range.size();
    // At most refine_samples returns: every ceil(n / refine_samples)-th.
    const std::size_t stride = (n + params_.refine_samples - 1) / params_.refine_samples;
    const float first = static_cast<float>(slot.geometry.angle(0));
    const float inv_step = static_cast<float>(1.0 / slot.geometry.step());
    double gate = params_.refine_gate_m;
    bool changed = false;
    for (std::size_t it = 0; it < params_.refine_iterations; ++it) {
        const float c = static_cast<float>(std::cos(d.phi)),
                    s = static_cast<float>(std::sin(d.phi));
        const float tx = static_cast<float>(d.x), ty = static_cast<float>(d.y);
        const float gate_f = static_cast<float>(gate);
        PointToLineSystem<double> sys;
        for (std::size_t j = 0; j < n; j += stride) {
            if (!slot.valid[j]) continue;
            const float px = slot.range[j] * dirs_.cos[j], py = slot.range[j] * dirs_.sin[j];
            const float qx = c * px - s * py + tx, qy = s * px + c * py + ty;
            const float u = (EvidenceFilter::approxAtan2(qy, qx) - first) * inv_step;
            if (!(u >= 0.0f) || !(u < static_cast<float>(n - 1))) continue;
            const std::size_t k0 = static_cast<std::size_t>(u), k1 = k0 + 1;
            if (!klink_[k0]) continue;
            float nx = 0.0f, ny = 0.0f, e = 0.0f;
            if (!pointToLine(kx_[k0], ky_[k0], kx_[k1], ky_[k1], qx, qy, nx, ny, e)) continue;
            if (!(std::abs(e) <= gate_f)) continue;
            sys.add(nx, ny, qx, qy, e);
        }
        gate = 0.5 * gate;
        if (sys.pairs < 12) break;
        if (!sys.step(d)) break;
        changed = true;
    }
    return changed;
}

ScanFusion::Result ScanFusion::fuse(Scan& kf) {
    Result res;
    const std::size_t n = kf.range.size();
    res.beams_valid = kf.countValid();
    res.scans_kept = count_;
    // 1. Noise from the keyframe itself.
    const double measured = measureSigma(kf, 4, scratch_);
    if (measured > 0.0) {
        const double s = std::max(params_.min_sigma_m, measured);
        sigma_smoothed_ = sigma_smoothed_ < 0.0 ? s : 0.8 * sigma_smoothed_ + 0.2 * s;
    }
    const double sigma = sigma_smoothed_ > 0.0 ? sigma_smoothed_ : params_.min_sigma_m;
    res.sigma = sigma;
    const std::size_t kept = count_;
    count_ = 0;  // whatever happens below, the ring starts again after this keyframe
    if (kept == 0 || !kf.odometry || n < 2) return res;
    const Frame f = frameOf(kf, sigma);
    if (params_.refine_iterations > 0) keyframeSurfaces(kf, f);  // for refine()
    // 2.-3. Each kept scan, oldest first, into column s of cand_.
    for (std::size_t s = 0; s < kept; ++s) {
        used_[s] = 0;
        const Slot& slot = slots_[(head_ + f.S - kept + s) % f.S];
        if (slot.geometry != f.g) continue;
        Pose2D d = between(f.kf_pose, slot.pose);
        if (std::hypot(d.x, d.y) > params_.max_step_m ||
            std::abs(wrapAngle(d.phi)) > params_.max_step_deg * kDeg)
            continue;
        if (params_.refine_iterations > 0 && refine(kf, slot, d)) ++res.scans_refined;
        project(slot, d, s, f);
        if (!agreesWithKeyframe(kf, s, f, res)) continue;
        used_[s] = 1;
        ++res.scans_used;
    }
    if (res.scans_used > 0) combine(kf, kept, f, res);
    return res;
}

ScanFusion::Frame ScanFusion::frameOf(const Scan& kf, double sigma) {
    Frame f;
    const std::size_t n = kf.range.size();
    f.g = kf.geometry;
    f.g.beams = n;
    dirs_.update(f.g);
    f.first = static_cast<float>(f.g.angle(0));
    f.inv_step = static_cast<float>(1.0 / f.g.step());
    f.S = params_.max_scans;
    cand_.assign(n * f.S, kInf);
    qx_.resize(n);
    qy_.resize(n);
    u_.resize(n);
    f.kf_pose = compose(*kf.odometry, kf.sensor_pose);
    f.sigma = sigma;
    f.gate = static_cast<float>(params_.gate_sigmas * std::sqrt(2.0) * sigma);
    f.noise = static_cast<float>(3.0 * std::sqrt(2.0) * sigma);
    const double dt = std::min(f.g.resolution(), 0.5 * kLambda);
    f.factor = static_cast<float>(std::sin(dt) / std::sin(kLambda - dt));
    f.span = static_cast<float>(params_.max_span_beams);
    return f;
}

// The keyframe's points and which consecutive returns are one surface (refine()'s targets).
void ScanFusion::keyframeSurfaces(const Scan& kf, const Frame& f) {
    const std::size_t n = kf.range.size();
    kx_.resize(n);
    ky_.resize(n);
    klink_.assign(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
        kx_[k] = kf.range[k] * dirs_.cos[k];
        ky_[k] = kf.range[k] * dirs_.sin[k];
    }
    for (std::size_t k = 0; k + 1 < n; ++k) {
        if (!kf.valid[k] || !kf.valid[k + 1]) continue;
        const float ex = kx_[k + 1] - kx_[k], ey = ky_[k + 1] - ky_[k];
        const float dmax = std::min(kf.range[k], kf.range[k + 1]) * f.factor + f.noise;
        klink_[k] = ex * ex + ey * ey <= dmax * dmax;
    }
}

// A kept scan moved into the keyframe's frame by d: each of its surface segments (consecutive
// returns within the breakpoint distance) cut by the keyframe's beams it spans; the nearest
// crossing per beam goes into column s of cand_.
void ScanFusion::project(const Slot& slot, const Pose2D& d, std::size_t s, const Frame& f) {
    const std::size_t n = f.g.beams;  // the keyframe's (the slot has its geometry)
    const float c = static_cast<float>(std::cos(d.phi)), sn = static_cast<float>(std::sin(d.phi));
    const float tx = static_cast<float>(d.x), ty = static_cast<float>(d.y);
    for (std::size_t j = 0; j < n; ++j) {
        if (!slot.valid[j]) continue;
        const float px = slot.range[j] * dirs_.cos[j], py = slot.range[j] * dirs_.sin[j];
        qx_[j] = c * px - sn * py + tx;
        qy_[j] = sn * px + c * py + ty;
        u_[j] = (EvidenceFilter::approxAtan2(qy_[j], qx_[j]) - f.first) * f.inv_step;
    }
    for (std::size_t j = 0; j + 1 < n; ++j) {
        if (!slot.valid[j] || !slot.valid[j + 1]) continue;
        const float ex = qx_[j + 1] - qx_[j], ey = qy_[j + 1] - qy_[j];
        const float dmax = std::min(slot.range[j], slot.range[j + 1]) * f.factor + f.noise;
        if (ex * ex + ey * ey > dmax * dmax) continue;  // a depth edge, not one surface
        const float ua = std::min(u_[j], u_[j + 1]), ub = std::max(u_[j], u_[j + 1]);
        if (!(ub - ua <= f.span) || !(ub >= 0.0f) || !(ua <= static_cast<float>(n - 1))) continue;
        const std::size_t k0 = static_cast<std::size_t>(std::ceil(std::max(0.0f, ua)));
        const std::size_t k1 = std::min(n - 1, static_cast<std::size_t>(std::floor(ub)));
        for (std::size_t k = k0; k <= k1; ++k) {
            // The beam k ray t (cos, sin) meets q_j + v e: t = (q_j x e) / (dir x e).
            const float den = dirs_.cos[k] * ey - dirs_.sin[k] * ex;
            const float num = qx_[j] * ey - qy_[j] * ex;
            float t = std::abs(den) > 1e-9f ? num / den : kInf;
            if (!(t > 0.0f) || !std::isfinite(t)) {  // along the beam: the nearer end
                if (std::abs(den) > 1e-9f) continue;
                t = std::min(std::hypot(qx_[j], qy_[j]), std::hypot(qx_[j + 1], qy_[j + 1]));
            }
            float& slot_k = cand_[k * f.S + s];
            slot_k = std::min(slot_k, t);
        }
    }
}

// The scan's median disagreement with the keyframe over its agreeing returns: true when within
// max_bias_sigmas (else counted misaligned); false too with fewer than kMinPairs returns.
bool ScanFusion::agreesWithKeyframe(const Scan& kf, std::size_t s, const Frame& f, Result& res) {
    scratch_.clear();
    for (std::size_t k = 0; k < kf.range.size(); ++k) {
        if (!kf.valid[k]) continue;
        const float diff = cand_[k * f.S + s] - kf.range[k];
        if (std::abs(diff) <= f.gate) scratch_.push_back(diff);
    }
    if (scratch_.size() < kMinPairs) return false;
    auto mid = scratch_.begin() + static_cast<std::ptrdiff_t>(scratch_.size() / 2);
    std::nth_element(scratch_.begin(), mid, scratch_.end());
    if (std::abs(*mid) > params_.max_bias_sigmas * f.sigma) {
        ++res.scans_misaligned;
        return false;
    }
    return true;
}

// 4. Per valid beam: its own range and the agreeing returns, by the estimator.
void ScanFusion::combine(Scan& kf, std::size_t kept, const Frame& f, Result& res) const {
    float vals[65];
    std::size_t agreeing_total = 0;
    for (std::size_t k = 0; k < kf.range.size(); ++k) {
        if (!kf.valid[k]) continue;
        const float r = kf.range[k];
        std::size_t m = 0;
        vals[m++] = r;
        for (std::size_t s = 0; s < kept; ++s) {
            if (!used_[s]) continue;
            const float v = cand_[k * f.S + s];
            if (std::abs(v - r) <= f.gate) vals[m++] = v;
        }
        if (m - 1 < params_.min_agreeing) continue;
        float est = 0.0f;
        if (params_.estimator == Estimator::Mean) {
            double sum = 0.0;
            for (std::size_t i = 0; i < m; ++i) sum += vals[i];
            est = static_cast<float>(sum / static_cast<double>(m));
        } else {
            std::sort(vals, vals + m);
            est = m % 2 ? vals[m / 2] : 0.5f * (vals[m / 2 - 1] + vals[m / 2]);
        }
        kf.range[k] = est;
        ++res.beams_fused;
        agreeing_total += m - 1;
    }
    if (res.beams_fused > 0)
        res.mean_scans_per_fused =
            static_cast<double>(agreeing_total) / static_cast<double>(res.beams_fused);
}

}  // namespace kfd
