#include "kfd/algorithms/evidence_filter.h"

#include "kfd/algorithms/point_to_line.h"
#include "kfd/algorithms/surface_run.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "kfd/algorithms/pose.h"

namespace kfd {

namespace {

constexpr double kDeg = kPi / 180.0;

/// Distance squared from (px, py) to the segment (ax, ay)-(bx, by).
inline float segmentDistance2(float px, float py, float ax, float ay, float bx, float by) {
    const float ux = bx - ax, uy = by - ay, wx = px - ax, wy = py - ay;
    const float uu = ux * ux + uy * uy;
    float t = uu > 0.0f ? (wx * ux + wy * uy) / uu : 0.0f;
    t = std::min(1.0f, std::max(0.0f, t));
    const float dx = wx - t * ux, dy = wy - t * uy;
    return dx * dx + dy * dy;
}

// sqrt(1.5): the residual of a beam against its two neighbours' line has variance 1.5 sigma^2.
constexpr double kResidualScale = 1.2247448713915889;

/// atan(a) / a for a in [0, 1]: a minimax polynomial (atan to ~1e-5 rad).
inline float atanUnit(float a) {
    const float s = a * a;
    return ((((-0.0117212f * s + 0.05265332f) * s - 0.11643287f) * s + 0.19354346f) * s -
            0.33262347f) *
               s +
           0.99997726f;
}

/// EvidenceFilter::approxAtan2, inlined where it runs per projected return.
inline float fastAtan2(float y, float x) {
    const float ax = std::abs(x), ay = std::abs(y);
    const float mx = std::max(ax, ay), mn = std::min(ax, ay);
    if (!(mx > 0.0f)) return 0.0f;
    const float a = mn / mx;
    float r = atanUnit(a) * a;
    if (ay > ax) r = 1.57079637f - r;
    if (x < 0.0f) r = 3.14159274f - r;
    return y < 0.0f ? -r : r;
}

/// `c ? a : b` by bit masks: GCC (-ftrapping-math) if-converts no floating-point select in an
/// omp simd loop, but vectorises these.
inline float pick(bool c, float a, float b) {
    std::uint32_t ua, ub;
    std::memcpy(&ua, &a, sizeof ua);
    std::memcpy(&ub, &b, sizeof ub);
    const std::uint32_t m = 0u - static_cast<std::uint32_t>(c);
    const std::uint32_t r = (ua & m) | (ub & ~m);
    float f;
    std::memcpy(&f, &r, sizeof f);
    return f;
}

/// fastAtan2 without branches (for omp simd loops): the same operations, the same results.
inline float fastAtan2Select(float y, float x) {
    const float ax = std::abs(x), ay = std::abs(y);
    const float mx = pick(ax < ay, ay, ax), mn = pick(ay < ax, ay, ax);  // std::max, std::min
    const float a = mn / mx;
    float r = atanUnit(a) * a;
    r = pick(ay > ax, 1.57079637f - r, r);
    r = pick(x < 0.0f, 3.14159274f - r, r);
    r = pick(y < 0.0f, -r, r);
    return pick(mx > 0.0f, r, 0.0f);
}

/// Points (x, y) moved by the rotation (c, s) and translation (tx, ty) into a reference's
/// frame (qx, qy), and their bracket positions u = (bearing - first) * inv_step in its beams:
/// one omp simd pass.
inline void projectPoints(std::size_t m, const float* x, const float* y, float c, float s, float tx,
                          float ty, float first, float inv_step, float* qx, float* qy, float* u) {
#pragma omp simd
    for (std::size_t j = 0; j < m; ++j) {
        const float px = c * x[j] - s * y[j] + tx, py = s * x[j] + c * y[j] + ty;
        qx[j] = px;
        qy[j] = py;
        u[j] = (fastAtan2Select(py, px) - first) * inv_step;
    }
}

/// The step-2 margin between two returns that each carry range noise sigma: 3 sigma of their
/// difference (3 sqrt(2) sigma).
inline double pairMargin(double sigma) { return 3.0 * std::sqrt(2.0) * sigma; }

}  // namespace

float EvidenceFilter::approxAtan2(float y, float x) { return fastAtan2(y, x); }

double EvidenceFilter::lineResidual(double a, double r, double b, double cos_res) {
    const double inv = 1.0 / a + 1.0 / b;
    if (!(inv > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return r - 2.0 * cos_res / inv;
}

void EvidenceFilter::initialize(const Params& p) {
    if (!(p.incidence_deg > 0.0 && p.incidence_deg < 90.0))
        throw ParameterError("incidence_deg", "incidence_deg must be in (0, 90)");
    if (!(p.sigma_m >= 0.0) || !std::isfinite(p.sigma_m))
        throw ParameterError("sigma_m", "sigma_m must be >= 0 (0 = estimated from the scans)");
    if (!(p.min_sigma_m > 0.0) || !std::isfinite(p.min_sigma_m))
        throw ParameterError("min_sigma_m", "min_sigma_m must be > 0");
    if (p.max_gap_beams > 16)
        throw ParameterError("max_gap_beams", "max_gap_beams must be in [0, 16]");
    if (!(p.min_object_size_m >= 0.0) || !std::isfinite(p.min_object_size_m))
        throw ParameterError("min_object_size_m", "min_object_size_m must be >= 0");
    if (p.max_small_points > 1000)
        throw ParameterError("max_small_points", "max_small_points must be in [0, 1000]");
    auto nonneg = [](double v) { return v >= 0.0 && std::isfinite(v); };
    if (!nonneg(p.pose_trans_error_m) || !nonneg(p.pose_rot_error_deg) ||
        !nonneg(p.motion_error_fraction) || !nonneg(p.moving_object_m))
        throw ParameterError("pose_error", "pose error terms must be finite and >= 0");
    if (!(p.max_step_m > 0.0) || !(p.max_step_deg > 0.0) || !std::isfinite(p.max_step_m) ||
        !std::isfinite(p.max_step_deg))
        throw ParameterError("max_step", "max_step_m and max_step_deg must be > 0");
    if (p.refine_iterations > 20 || p.refine_samples < 1 || !(p.refine_gate_m > 0.0) ||
        !std::isfinite(p.refine_gate_m))
        throw ParameterError("refine", "refine_iterations <= 20, refine_samples >= 1, gate > 0");
    if (p.tracked_refine_iterations > p.refine_iterations ||
        p.tracked_refine_samples > p.refine_samples || p.tracked_refine_samples < 1)
        throw ParameterError("tracked_refine",
                             "tracked_refine_iterations <= refine_iterations, "
                             "1 <= tracked_refine_samples <= refine_samples");
    if (!(p.max_removed_fraction > 0.0 && p.max_removed_fraction <= 1.0))
        throw ParameterError("max_removed_fraction", "max_removed_fraction must be in (0, 1]");
    if (!(p.max_confirmed_fraction >= 0.0 && p.max_confirmed_fraction <= 1.0))
        throw ParameterError("max_confirmed_fraction", "max_confirmed_fraction must be in [0, 1]");
    if (!(p.confirm_support > 0.0 && p.confirm_support <= 1.0))
        throw ParameterError("confirm_support", "confirm_support must be in (0, 1]");
    if (p.temporal_scans > 16)
        throw ParameterError("temporal_scans", "temporal_scans must be in [0, 16]");
    if (p.surface_min_beams < 2 || p.surface_min_beams > 1000)
        throw ParameterError("surface_min_beams", "surface_min_beams must be in [2, 1000]");
    if (!(p.surface_sigmas >= 0.0 && p.surface_sigmas <= 100.0))
        throw ParameterError("surface_sigmas", "surface_sigmas must be in [0, 100]");
    params_ = p;
    raw_.assign(p.temporal_scans, RawScan{});
    residuals_.reserve(2 * (2 * p.refine_samples + 2));
    align_.reserve(5 * (2 * p.refine_samples + 2));
    lambda_ = p.incidence_deg * kDeg;
    reset();
}

void EvidenceFilter::reset() {
    refs_[0].present = refs_[1].present = false;
    sigma_smoothed_ = -1.0;
    measured_smoothed_ = -1.0;
    have_pose_ = false;
    raw_next_ = raw_count_ = 0;
}

void EvidenceFilter::observe(const Scan& scan, const Tracked* tracked) {
    if (!raw_.empty() && params_.temporal) keepRaw(scan, tracked);
}

void EvidenceFilter::RawScan::copy(const Scan& scan, const Tracked* tracked) {
    geometry = scan.geometry;
    range.assign(scan.range.begin(), scan.range.end());
    valid.assign(scan.valid.begin(), scan.valid.end());
    has_odom = scan.odometry.has_value();
    odom = has_odom ? compose(*scan.odometry, scan.sensor_pose) : Pose2D{};
    track = SensorTrack::of(scan, tracked);
}

EvidenceFilter::SensorTrack EvidenceFilter::SensorTrack::of(const Scan& scan,
                                                            const Tracked* tracked) {
    SensorTrack t;
    if (tracked == nullptr) return t;
    t.present = true;
    t.pose = compose(tracked->pose, scan.sensor_pose);
    t.rms_m = tracked->rms_m;
    return t;
}

void EvidenceFilter::keepRaw(const Scan& scan, const Tracked* tracked) {
    raw_[raw_next_].copy(scan, tracked);
    raw_next_ = (raw_next_ + 1) % raw_.size();
    raw_count_ = std::min(raw_count_ + 1, raw_.size());
}

bool EvidenceFilter::convertRaw(const Scan& scan, std::size_t age, double sigma) {
    if (age >= raw_count_) return false;
    return convertInto(raw_[(raw_next_ + raw_.size() - 1 - age) % raw_.size()], recent_, scan,
                       sigma);
}

bool EvidenceFilter::convertInto(const RawScan& w, Reference& r, const Scan& scan, double sigma) {
    const std::size_t n = scan.range.size();
    if (w.geometry != scan.geometry || w.range.size() != n) return false;
    r.present = true;
    r.geometry = w.geometry;
    r.range.assign(w.range.begin(), w.range.end());
    r.valid.resize(n);
    r.x.resize(n);
    r.y.resize(n);
    r.link.resize(n);
    if (n > 0) r.link[n - 1] = 0;  // the others are all written below
    r.evidence.clear();            // no evidence of its own: nothing is tracked against it
    r.has_odom = w.has_odom;
    r.odom = r.pose = w.odom;
    r.track = w.track;
    // Branch-free passes (this runs once per keyframe over every beam).
    const float* range = w.range.data();
    const std::uint8_t* wv = w.valid.data();
    const float* cs = dirs_.cos.data();
    const float* sn = dirs_.sin.data();
    std::uint8_t* valid = r.valid.data();
    float* x = r.x.data();
    float* y = r.y.data();
    const float max_range = kMaxScanRangeM;
#pragma omp simd
    for (std::size_t k = 0; k < n; ++k) {
        const float rk = range[k];
        valid[k] = static_cast<std::uint8_t>((wv[k] != 0) & (rk >= 0.0f) & (rk <= max_range));
        x[k] = rk * cs[k];
        y[k] = rk * sn[k];
    }
    // Links: the breakpoint test of step 2 between neighbouring returns (one surface).
    const double dt = std::min(static_cast<double>(res_), 0.5 * lambda_);
    const float factor = static_cast<float>(std::sin(dt) / std::sin(lambda_ - dt));
    const float noise = static_cast<float>(pairMargin(sigma));
    std::uint8_t* link = r.link.data();
    const std::size_t pairs = n > 0 ? n - 1 : 0;
#pragma omp simd
    for (std::size_t k = 0; k < pairs; ++k) {
        const float dx = x[k + 1] - x[k], dy = y[k + 1] - y[k];
        const float dmax = std::min(range[k], range[k + 1]) * factor + noise;
        link[k] =
            static_cast<std::uint8_t>(valid[k] & valid[k + 1] & (dx * dx + dy * dy <= dmax * dmax));
    }
    return true;
}

EvidenceFilter::Projection EvidenceFilter::rawProjection(const Scan& scan, const Reference& ref,
                                                         double sigma, double* base) const {
    Projection pr;
    Pose2D d;  // this scan's sensor in the raw scan's frame
    double spread = 0.0;
    if (trackedStep(scan, ref, d, true)) {  // the tracker placed both: its residual is the spread
        if (!projection(ref, d, sigma).usable) return pr;
        spread = std::max(tracked_->rms_m, ref.track.rms_m);
    } else {
        if (scan.odometry && ref.has_odom)
            d = between(ref.odom, compose(*scan.odometry, scan.sensor_pose));
        else if (scan.odometry || ref.has_odom)
            return pr;  // no common frame
        if (!projection(ref, d, sigma).usable) return pr;
        if (!refineStep(scan, ref, d, &spread)) return pr;  // no alignment: no margin to trust
    }
    pr = projection(ref, d, sigma);
    // The margin from what was measured: the larger of the two scans' range noise and the
    // alignment's own residual spread (3 standard deviations), plus the odometry-error share
    // of this (short) step; no constant pose error.
    *base = 3.0 * std::max(std::sqrt(2.0) * sigma, spread);
    pr.m0 = static_cast<float>(*base + params_.motion_error_fraction * std::hypot(d.x, d.y));
    pr.m1 = static_cast<float>(params_.motion_error_fraction * std::abs(d.phi));
    return pr;
}

EvidenceFilter::Projection EvidenceFilter::recentProjection(const Scan& scan, std::size_t age,
                                                            double sigma, Result& res) {
    if (!convertRaw(scan, age, sigma)) return Projection{};
    double base = 0.0;
    const Projection pr = rawProjection(scan, recent_, sigma, &base);
    if (pr.usable && age == 0) res.recent_margin_m = base;
    return pr;
}

EvidenceFilter::Projection EvidenceFilter::nextProjection(const Scan& scan, double sigma,
                                                          Result& res) {
    // Step 3c: the next scan, copied and converted like a raw scan of step 3b, aligned the
    // same way and with the same margins.
    next_raw_.copy(*next_, nullptr);  // not tracked yet: aligned by odometry and refined
    if (!convertInto(next_raw_, next_ref_, scan, sigma)) return Projection{};
    double base = 0.0;
    const Projection pr = rawProjection(scan, next_ref_, sigma, &base);
    res.next = pr.usable;
    return pr;
}

void EvidenceFilter::updateTables(const ScanGeometry& g) {
    dirs_.update(g);
    first_ = static_cast<float>(g.angle(0));
    inv_step_ = g.beams > 1 ? static_cast<float>(1.0 / g.step()) : 0.0f;
    res_ = static_cast<float>(g.resolution());
}

double EvidenceFilter::estimateSigma(const Scan& scan) {
    if (params_.sigma_m > 0.0) return params_.sigma_m;
    // The lower decile of |e| over every fourth beam: flat surfaces dominate it, corners and
    // clutter (which inflate the median on a 1-degree scanner) do not.
    // decile of |N(0, 1.5 s^2)| = 0.1257 sqrt(1.5) s.
    const std::size_t n = scan.range.size();
    const float cos_res = std::cos(res_);
    scratch_.clear();
    for (std::size_t i = 1; i + 1 < n; i += 4) {
        if (!scan.valid[i - 1] || !scan.valid[i] || !scan.valid[i + 1]) continue;
        const float a = scan.range[i - 1], r = scan.range[i], b = scan.range[i + 1];
        if (!(a + b > 0.0f)) continue;
        scratch_.push_back(std::abs(r - 2.0f * cos_res * a * b / (a + b)));
    }
    if (scratch_.size() < 16) return sigma_smoothed_ > 0.0 ? sigma_smoothed_ : params_.min_sigma_m;
    auto q = scratch_.begin() + static_cast<std::ptrdiff_t>(scratch_.size() / 10);
    std::nth_element(scratch_.begin(), q, scratch_.end());
    const double measured = static_cast<double>(*q) / (0.1257 * kResidualScale);
    const double sigma = std::max(params_.min_sigma_m, measured);
    sigma_smoothed_ = sigma_smoothed_ < 0.0 ? sigma : 0.8 * sigma_smoothed_ + 0.2 * sigma;
    measured_smoothed_ =
        measured_smoothed_ < 0.0 ? measured : 0.8 * measured_smoothed_ + 0.2 * measured;
    return sigma_smoothed_;
}

void EvidenceFilter::segment(const Scan& scan, double sigma, Clusters& out) {
    const Breakpoints bp = breakpoints(sigma);
    linkNeighbours(scan, sigma, bp);
    std::size_t first_valid = 0, last = 0;
    labelSegments(scan, bp, out, first_valid, last);
    joinAcrossSeam(scan, bp, first_valid, last, out);
    out.mean_range.resize(out.size.size());
    for (std::size_t c = 0; c < out.size.size(); ++c)
        out.mean_range[c] = sums_[c] / static_cast<float>(out.size[c]);
    out.noise.assign(out.size.size(), 0);
}

EvidenceFilter::Breakpoints EvidenceFilter::breakpoints(double sigma) const {
    // Breakpoint distance / r_min per beam step, for steps 1..max_gap + 1 (dtheta < lambda).
    Breakpoints bp;
    bp.max_step = params_.max_gap_beams + 1;
    for (std::size_t k = 1; k <= bp.max_step; ++k) {
        const double dt = std::min(static_cast<double>(k) * res_, 0.5 * lambda_);
        bp.factor[k] = static_cast<float>(std::sin(dt) / std::sin(lambda_ - dt));
    }
    bp.noise = static_cast<float>(pairMargin(sigma));
    return bp;
}

void EvidenceFilter::linkNeighbours(const Scan& scan, double sigma, const Breakpoints& bp) {
    const std::size_t n = scan.range.size();
    const float cos_res = std::cos(res_);
    // On a line with both neighbours: |e| <= 3 sqrt(1.5) sigma, written without the division
    // (|r (a + b) - 2 cos(res) a b| <= tol (a + b)).
    const float tol = static_cast<float>(3.0 * kResidualScale * sigma);
    line_.resize(n);
    link_.resize(n);
    const std::uint8_t* valid = scan.valid.data();
    const float* range = scan.range.data();
    const float* x = x_.data();
    const float* y = y_.data();
    std::uint8_t* line = line_.data();
    std::uint8_t* link = link_.data();
    const std::size_t pairs = n > 0 ? n - 1 : 0;
    if (n > 0) line[0] = line[n - 1] = 0;
        // Branch-free passes over every beam (the same arithmetic as a test per beam).
#pragma omp simd
    for (std::size_t i = 1; i < pairs; ++i) {
        const float a = range[i - 1], r = range[i], b = range[i + 1];
        const float sum = a + b;
        line[i] =
            static_cast<std::uint8_t>((valid[i - 1] != 0) & (valid[i] != 0) & (valid[i + 1] != 0) &
                                      (std::abs(r * sum - 2.0f * cos_res * a * b) <= tol * sum));
    }
    // Neighbouring returns: one surface within the breakpoint distance or on a line together.
    const float factor1 = bp.factor[1];
    const float noise = bp.noise;
    if (n > 0) link[n - 1] = 0;
#pragma omp simd
    for (std::size_t i = 0; i < pairs; ++i) {
        const float dx = x[i + 1] - x[i], dy = y[i + 1] - y[i];
        const float dmax = std::min(range[i], range[i + 1]) * factor1 + noise;
        link[i] = static_cast<std::uint8_t>(
            (valid[i] != 0) & (valid[i + 1] != 0) &
            ((dx * dx + dy * dy <= dmax * dmax) | (line[i] & line[i + 1])));
    }
}

void EvidenceFilter::reserveSegmentBuffers(std::size_t n) {
    // Sizes, range sums and flanked flags per segment (at most n), in buffers kept at their
    // largest (no zero fill per scan); the sizes are copied out at the end.
    if (sizes_.size() < n) sizes_.resize(n);
    if (sums_.size() < n) sums_.resize(n);
    if (flanked_.size() < n) flanked_.resize(n);
}

void EvidenceFilter::labelSegments(const Scan& scan, const Breakpoints& bp, Clusters& out,
                                   std::size_t& first_valid, std::size_t& last) {
    // Segments (at most n): returns across up to max_gap_beams missing beams are tested here.
    const std::size_t n = scan.range.size();
    const std::uint8_t* valid = scan.valid.data();
    const float* range = scan.range.data();
    const float* x = x_.data();
    const float* y = y_.data();
    std::uint8_t* link = link_.data();
    out.label.resize(n);  // every beam written below (-1: no return)
    reserveSegmentBuffers(n);
    std::uint32_t* size = sizes_.data();
    float* sums = sums_.data();
    std::uint8_t* flanked = flanked_.data();
    std::int32_t* label = out.label.data();
    std::size_t count = 0;
    first_valid = 0;
    while (first_valid < n && !valid[first_valid]) label[first_valid++] = -1;
    last = n;  // the previous valid beam
    // The open segment's size and range sum stay in registers until the next one starts.
    std::uint32_t cur_size = 0;
    float cur_sum = 0.0f;
    for (std::size_t i = first_valid; i < n; ++i) {
        if (!valid[i]) {
            label[i] = -1;
            continue;
        }
        bool linked = false;
        if (i == last + 1) {
            linked = link[last] != 0;
        } else if (last < n && i - last <= bp.max_step) {
            const float dx = x[i] - x[last], dy = y[i] - y[last];
            const float dmax = std::min(range[last], range[i]) * bp.factor[i - last] + bp.noise;
            linked = dx * dx + dy * dy <= dmax * dmax;
            link[last] = static_cast<std::uint8_t>(linked);
        }
        if (!linked) {
            // Flanked (step 4): another segment's return within max_gap_beams + 1 beams.
            const auto near = static_cast<std::uint8_t>(last < n && i - last <= bp.max_step);
            if (count > 0) {
                size[count - 1] = cur_size;
                sums[count - 1] = cur_sum;
                flanked[count - 1] |= near;
            }
            flanked[count] = near;
            ++count;
            cur_size = 0;
            cur_sum = 0.0f;
        }
        label[i] = static_cast<std::int32_t>(count - 1);
        ++cur_size;
        cur_sum += range[i];
        last = i;
    }
    if (count > 0) {
        size[count - 1] = cur_size;
        sums[count - 1] = cur_sum;
    }
    out.size.assign(sizes_.begin(), sizes_.begin() + static_cast<std::ptrdiff_t>(count));
}

void EvidenceFilter::joinAcrossSeam(const Scan& scan, const Breakpoints& bp,
                                    std::size_t first_valid, std::size_t last, Clusters& out) {
    // A scanner closing the circle: the last segment continues the first across the seam.
    const std::size_t n = scan.range.size();
    if (out.size.size() <= 1 || last >= n || first_valid >= last) return;
    const double gap =
        static_cast<double>(n - 1 - last + first_valid) * res_ + scan.geometry.seamGap();
    if (gap > static_cast<double>(bp.max_step) * res_ + 1e-9) return;
    const float dx = x_[first_valid] - x_[last], dy = y_[first_valid] - y_[last];
    const double dt = std::min(gap, 0.5 * lambda_);
    const float dmax = std::min(scan.range[last], scan.range[first_valid]) *
                           static_cast<float>(std::sin(dt) / std::sin(lambda_ - dt)) +
                       bp.noise;
    if (dx * dx + dy * dy > dmax * dmax) return;
    const std::size_t tail = out.size.size() - 1;
    for (std::size_t i = 0; i < n; ++i)
        if (out.label[i] == static_cast<std::int32_t>(tail)) out.label[i] = 0;
    out.size[0] += out.size[tail];
    sums_[0] += sums_[tail];
    flanked_[0] |= flanked_[tail];
    out.size.pop_back();
    link_[last] = 1;
}

EvidenceFilter::Projection EvidenceFilter::projection(const Reference& ref, const Pose2D& d,
                                                      double sigma) const {
    Projection pr;
    const double step_t = std::hypot(d.x, d.y), step_r = std::abs(d.phi);
    pr.usable = step_t <= params_.max_step_m && step_r <= params_.max_step_deg * kDeg;
    pr.m0 = static_cast<float>(pairMargin(sigma) + params_.pose_trans_error_m +
                               params_.motion_error_fraction * step_t);
    pr.m1 = static_cast<float>(params_.pose_rot_error_deg * kDeg +
                               params_.motion_error_fraction * step_r);
    pr.c = static_cast<float>(std::cos(d.phi));
    pr.s = static_cast<float>(std::sin(d.phi));
    pr.tx = static_cast<float>(d.x);
    pr.ty = static_cast<float>(d.y);
    pr.ref = &ref;
    return pr;
}

std::uint8_t EvidenceFilter::classify(const Projection& pr, float x, float y,
                                      bool free_test) const {
    const float qx = pr.c * x - pr.s * y + pr.tx, qy = pr.s * x + pr.c * y + pr.ty;
    return classifyAt(pr, qx, qy, (fastAtan2(qy, qx) - first_) * inv_step_, free_test);
}

std::uint8_t EvidenceFilter::classifyAt(const Projection& pr, float qx, float qy, float u,
                                        bool free_test) const {
    const Reference& ref = *pr.ref;
    const std::size_t rn = ref.range.size();
    if (!(u >= 0.0f) || !(u < static_cast<float>(rn - 1))) return kUnknown;  // unseen before
    const std::size_t k0 = static_cast<std::size_t>(u), k1 = k0 + 1;
    const float rho = std::sqrt(qx * qx + qy * qy);
    const float m = pr.m0 + pr.m1 * rho;
    const float arc = rho * res_;  // the spread of a beam's position within its bracket
    // Free space: both bracketing beams passed this place. On one surface (linked) that
    // surface lies beyond the nearer of the two; across a depth edge an object could hide
    // between the beams, so the margin adds the arc.
    if (free_test && ref.valid[k0] && ref.valid[k1]) {
        const float mf = ref.link[k0] ? m : m + arc;
        if (ref.range[k0] > rho + mf && ref.range[k1] > rho + mf)
            return !ref.evidence.empty() && trackedMotion(ref, qx, qy, rho, k0) ? kTracked : kFree;
    }
    // Supported: a reference return within m plus one beam's arc (the same object sampled at
    // other angles), a beam either side of the bracket, or the reference surface segment
    // between the bracketing returns within m.
    const float ms2 = (m + arc) * (m + arc);
    const std::size_t lo = k0 > 0 ? k0 - 1 : 0, hi = std::min(rn - 1, k1 + 1);
    for (std::size_t k = lo; k <= hi; ++k) {
        if (!ref.valid[k]) continue;
        const float dx = qx - ref.x[k], dy = qy - ref.y[k];
        if (dx * dx + dy * dy <= ms2) return kSupported;
    }
    if (ref.valid[k0] && ref.valid[k1] && ref.link[k0] &&
        segmentDistance2(qx, qy, ref.x[k0], ref.y[k0], ref.x[k1], ref.y[k1]) <= m * m)
        return kSupported;
    return kUnknown;
}

bool EvidenceFilter::trackedMotion(const Reference& ref, float qx, float qy, float rho,
                                   std::size_t k0) const {
    // A return in the reference's own free space near here: a moving object seen before.
    const double reach = params_.moving_object_m;
    if (!(reach > 0.0)) return false;
    const std::size_t rn = ref.range.size();
    const std::size_t w = std::min<std::size_t>(
        64, static_cast<std::size_t>(reach / std::max(0.05, static_cast<double>(rho * res_))) + 1);
    const std::size_t lo = k0 > w ? k0 - w : 0, hi = std::min(rn - 1, k0 + 1 + w);
    const float r2 = static_cast<float>(reach * reach);
    for (std::size_t k = lo; k <= hi; ++k) {
        if (!ref.valid[k] || (ref.evidence[k] != kFree && ref.evidence[k] != kTracked)) continue;
        const float dx = qx - ref.x[k], dy = qy - ref.y[k];
        if (dx * dx + dy * dy <= r2) return true;
    }
    return false;
}

bool EvidenceFilter::refineStep(const Scan& scan, const Reference& ref, Pose2D& d, double* spread,
                                std::size_t skip, std::size_t samples) const {
    // Projective point-to-line alignment: each sampled return is projected into the reference
    // scan and paired with the reference segment between its two bracketing beams (when they
    // are one surface); Gauss-Newton on the distances to those lines corrects the step. The
    // gate halves per iteration down to 0.1 m; too few pairs keep the step as it is.
    const std::size_t n = scan.range.size(), rn = ref.range.size();
    if (params_.refine_iterations <= skip || rn < 2) return false;
    const std::size_t stride =
        std::max<std::size_t>(1, n / (samples > 0 ? samples : params_.refine_samples));
    // The sampled returns, gathered once; per iteration their projections and bracket
    // positions in one omp simd pass, then the pairs.
    const std::size_t cap = n / stride + 1;  // within the capacity reserved by initialize()
    residuals_.resize(2 * cap);              // two iterations' residuals: the spread's and the next
    align_.resize(5 * cap);
    float* sx = align_.data();
    float* sy = sx + cap;
    float* qxs = sy + cap;
    float* qys = qxs + cap;
    float* us = qys + cap;
    const std::size_t m = sampleReturns(scan, stride, sx, sy);
    float* spread_of = nullptr;  // the residuals the spread is taken of (the last system used)
    std::size_t spread_n = 0;
    double gate = std::max(std::ldexp(params_.refine_gate_m, -static_cast<int>(skip)), 0.1);
    bool changed = false;
    for (std::size_t it = skip; it < params_.refine_iterations; ++it) {
        const float c = static_cast<float>(std::cos(d.phi)),
                    s = static_cast<float>(std::sin(d.phi));
        projectPoints(m, sx, sy, c, s, static_cast<float>(d.x), static_cast<float>(d.y), first_,
                      inv_step_, qxs, qys, us);
        PointToLineSystem<float> sys;
        float* residuals = residuals_.data() + (it % 2) * cap;
        const std::size_t kept =
            pairWithLines(ref, m, qxs, qys, us, static_cast<float>(gate), sys, residuals);
        gate = std::max(0.5 * gate, 0.1);
        if (sys.pairs < 12) break;
        spread_of = residuals;
        spread_n = kept;
        if (!sys.step(d)) break;
        changed = true;
    }
    // The robust spread of the last system's residuals (before its step).
    if (spread && spread_of) {
        float* mid = spread_of + spread_n / 2;
        std::nth_element(spread_of, mid, spread_of + spread_n);
        *spread = 1.4826 * static_cast<double>(*mid);
    }
    return changed;
}

std::size_t EvidenceFilter::sampleReturns(const Scan& scan, std::size_t stride, float* sx,
                                          float* sy) const {
    const std::size_t n = scan.range.size();
    // Raw pointers: the stores below cannot alias the vectors' own pointers then.
    const std::uint8_t* valid = scan.valid.data();
    const float* px = x_.data();
    const float* py = y_.data();
    std::size_t m = 0;
    for (std::size_t i = 0; i < n; i += stride) {
        if (!valid[i]) continue;
        sx[m] = px[i];
        sy[m] = py[i];
        ++m;
    }
    return m;
}

std::size_t EvidenceFilter::pairWithLines(const Reference& ref, std::size_t m, const float* qxs,
                                          const float* qys, const float* us, float gate,
                                          PointToLineSystem<float>& sys, float* residuals) {
    const std::uint8_t* rvalid = ref.valid.data();
    const std::uint8_t* rlink = ref.link.data();
    const float* rx = ref.x.data();
    const float* ry = ref.y.data();
    const float u_max = static_cast<float>(ref.range.size() - 1);
    std::size_t kept = 0;
    for (std::size_t j = 0; j < m; ++j) {
        const float u = us[j];
        if (!(u >= 0.0f) || !(u < u_max)) continue;
        const std::size_t k0 = static_cast<std::size_t>(u), k1 = k0 + 1;
        if (!rvalid[k0] || !rvalid[k1] || !rlink[k0]) continue;
        const float qx = qxs[j], qy = qys[j];
        float nx = 0.0f, ny = 0.0f, e = 0.0f;
        if (!pointToLine(rx[k0], ry[k0], rx[k1], ry[k1], qx, qy, nx, ny, e)) continue;
        if (std::abs(e) > gate) continue;
        sys.add(nx, ny, qx, qy, e);
        residuals[kept++] = std::abs(e);
    }
    return kept;
}

bool EvidenceFilter::temporalEvidence(const Scan& scan, const Clusters& out, double sigma,
                                      Result& res, bool recent) {
    have_pose_ = false;
    if (!params_.temporal) return false;
    // 3b. The raw scan just before (tight margins from its own alignment), when kept.
    Projection pt;
    if (recent) pt = recentProjection(scan, 0, sigma, res);
    res.recent = pt.usable;
    // 3c. The raw scan just after (next_scan), the same way.
    Projection pn;
    if (recent && next_) pn = nextProjection(scan, sigma, res);
    const Projection p0 = keyframeProjection(scan, sigma, res);
    if (!pt.usable && !pn.usable && !p0.usable) return false;
    recent_ev_.assign(pt.usable || pn.usable ? scan.range.size() : 0, kUnknown);
    const std::size_t listed = listReturnsToJudge(out);
    const std::size_t unknowns = judgeListed(out, listed, pt, pn, p0, res);
    object_support_.assign(spike_candidates_.size(), 0);
    markObjectSupport(pt);
    markObjectSupport(pn);
    markObjectSupport(p0);
    supportFromOlder(scan, out, sigma, unknowns, recent, res);
    return true;
}

EvidenceFilter::Projection EvidenceFilter::keyframeProjection(const Scan& scan, double sigma,
                                                              Result& res) {
    // This scan's sensor in the newest keyframe's frame (track_alignment: the tracker's step
    // where it placed both), refined from a start: the odometry step where both scans carry
    // odometry (and track_keyframe_start is off), else the tracker's step where it placed both
    // (its alignment did the schedule's first steps), else zero motion (laser only).
    Projection p0;
    const Reference& r0 = refs_[0];
    if (!r0.present || r0.geometry != scan.geometry) return p0;
    Pose2D d;
    const bool tracked = trackedStep(scan, r0, d, false);
    const bool odometry = scan.odometry && r0.has_odom;
    const bool start =
        !tracked && (params_.track_keyframe_start || !odometry) && placedByTracker(scan, r0, d);
    const std::size_t skip =
        start ? params_.refine_iterations - params_.tracked_refine_iterations : 0;
    if (!tracked && !start) {
        if (odometry)
            d = between(r0.odom, compose(*scan.odometry, scan.sensor_pose));
        else if (scan.odometry || r0.has_odom)
            return p0;  // odometry appeared or vanished: no common frame
    }
    if (!projection(r0, d, sigma).usable) return p0;
    if (!tracked)
        res.refined =
            refineStep(scan, r0, d, nullptr, skip, start ? params_.tracked_refine_samples : 0);
    p0 = projection(r0, d, sigma);
    pose_ = compose(r0.pose, d);
    have_pose_ = true;
    return p0;
}

std::size_t EvidenceFilter::listReturnsToJudge(const Clusters& out) {
    // Every return off a line, every return of a short segment, and every fourth return along
    // a line (enough to tell how much of a surface lies in free space).
    const std::size_t n = out.label.size();
    if (unknown_.size() < n) unknown_.resize(n);      // kept at its largest: no refill per scan
    if (batch_.size() < 5 * n) batch_.resize(5 * n);  // kept at its largest
    const std::int32_t* labels = out.label.data();
    const std::uint32_t* sizes = out.size.data();
    const std::uint8_t* line = line_.data();
    std::uint32_t* unknown = unknown_.data();
    float* bx = batch_.data();
    float* by = bx + n;
    std::size_t listed = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::int32_t label = labels[i];
        if (label < 0) continue;
        if (line[i] && (i & 3u) != 0 && sizes[static_cast<std::size_t>(label)] >= 8) continue;
        unknown[listed] = static_cast<std::uint32_t>(i);
        bx[listed] = x_[i];
        by[listed] = y_[i];
        ++listed;
    }
    return listed;
}

std::size_t EvidenceFilter::judgeListed(const Clusters& out, std::size_t listed,
                                        const Projection& pt, const Projection& pn,
                                        const Projection& p0, Result& res) {
    free_in_.assign(out.count(), 0);
    free_off_line_in_.assign(out.count(), 0);
    supported_in_.assign(out.count(), 0);
    classified_in_.assign(out.count(), 0);
    const std::size_t n = out.label.size();
    const std::int32_t* labels = out.label.data();
    const float* x = x_.data();
    const float* y = y_.data();
    std::uint32_t* unknown = unknown_.data();
    // The listed returns' projections and bracket positions in the first reference asked
    // (one omp simd pass).
    float* bx = batch_.data();
    float* by = bx + n;
    float* bqx = by + n;
    float* bqy = bqx + n;
    float* bu = bqy + n;
    const Projection& first_pr = pt.usable ? pt : pn.usable ? pn : p0;
    projectPoints(listed, bx, by, first_pr.c, first_pr.s, first_pr.tx, first_pr.ty, first_,
                  inv_step_, bqx, bqy, bu);
    std::size_t unknowns = 0;  // written over the list, behind the reading position
    for (std::size_t j = 0; j < listed; ++j) {
        const std::size_t i = unknown[j];
        const auto c = static_cast<std::size_t>(labels[i]);
        // The raw scan just before decides first; the keyframe decides what it left unknown,
        // and a return free just before is still tracked when the keyframe saw a moving object
        // here.
        std::uint8_t e = classifyAt(first_pr, bqx[j], bqy[j], bu[j], true);
        if (pt.usable && pn.usable && e != kSupported) {  // 3c: either raw neighbour's support
            const std::uint8_t en = classify(pn, x[i], y[i], true);
            if (en != kUnknown) e = en;
        }
        if (pt.usable || pn.usable) {
            if (!recent_ev_.empty()) recent_ev_[i] = e;  // the raw neighbours' verdict (step 5)
            if (e == kFree && p0.usable && classify(p0, x[i], y[i], true) == kTracked) e = kTracked;
            if (e == kUnknown && p0.usable) e = classify(p0, x[i], y[i], true);
        }
        evidence_[i] = e;
        ++classified_in_[c];
        if (e == kFree) {
            ++free_in_[c];
            free_off_line_in_[c] += line_[i] ? 0u : 1u;
            ++res.free_points;
        } else if (e == kSupported) {
            ++supported_in_[c];
            ++res.supported;
        } else if (e == kTracked) {
            ++res.tracked;
        } else {
            unknown[unknowns++] = static_cast<std::uint32_t>(i);
        }
    }
    return unknowns;
}

void EvidenceFilter::supportFromOlder(const Scan& scan, const Clusters& out, double sigma,
                                      std::size_t unknowns, bool recent, Result& res) {
    // The keyframe before it (and the older raw scans) can support what the newest could not
    // (a thin object between two beams, a return among dropouts); they never overrule free
    // space.
    auto support = [&](const Projection& p) {
        for (std::size_t j = 0; j < unknowns; ++j) {
            const std::uint32_t i = unknown_[j];
            if (evidence_[i] == kUnknown && classify(p, x_[i], y_[i], false) == kSupported) {
                evidence_[i] = kSupported;
                ++supported_in_[static_cast<std::size_t>(out.label[i])];
                ++res.supported;
            }
        }
        markObjectSupport(p);
    };
    // A spike that only a smooth surface supported so far: an older view may have seen an
    // object there.
    bool pending = false;
    if (params_.spike_object_support)
        for (std::size_t j = 0; j < spike_candidates_.size(); ++j)
            pending =
                pending || (evidence_[spike_candidates_[j]] == kSupported && !object_support_[j]);
    const Reference& r1 = refs_[1];
    if (have_pose_ && r1.present && r1.geometry == scan.geometry && (unknowns > 0 || pending)) {
        const Projection p1 = projection(r1, between(r1.pose, pose_), sigma);
        if (p1.usable) support(p1);
    }
    for (std::size_t age = 1; recent && age < raw_count_ && (unknowns > 0 || pending); ++age) {
        const Projection pa = recentProjection(scan, age, sigma, res);
        if (pa.usable) support(pa);
    }
}

void EvidenceFilter::keepAsReference(const Scan& scan) {
    if (!params_.temporal) {
        refs_[0].present = refs_[1].present = false;
        return;
    }
    std::swap(refs_[0], refs_[1]);  // the newest becomes the older; buffers are reused
    Reference& r = refs_[0];
    r.present = true;
    r.geometry = scan.geometry;
    r.range = scan.range;
    r.valid = scan.valid;
    r.link.swap(link_);
    r.evidence.swap(evidence_);
    r.x.swap(x_);
    r.y.swap(y_);
    r.has_odom = scan.odometry.has_value();
    r.odom = r.has_odom ? compose(*scan.odometry, scan.sensor_pose) : Pose2D{};
    // The refined pose chains the alignments; without one the odometry (or the origin) starts
    // a new chain, and the older keyframe is no longer in it.
    r.pose = have_pose_ ? pose_ : r.odom;
    if (!have_pose_) refs_[1].present = false;
    r.track = SensorTrack::of(scan, tracked_);
}

bool EvidenceFilter::trackedStep(const Scan& scan, const Reference& ref, Pose2D& d,
                                 bool raw) const {
    const bool use = params_.track_alignment || (raw && params_.track_raw_alignment);
    return use && placedByTracker(scan, ref, d);
}

bool EvidenceFilter::placedByTracker(const Scan& scan, const Reference& ref, Pose2D& d) const {
    if (tracked_ == nullptr || !ref.track.present) return false;
    d = between(ref.track.pose, compose(tracked_->pose, scan.sensor_pose));
    return true;
}

EvidenceFilter::Result EvidenceFilter::filter(Scan& scan, Clusters& out, const Scan* next) {
    return filter(scan, out, next, nullptr);
}

EvidenceFilter::Result EvidenceFilter::filter(Scan& scan, Clusters& out, const Scan* next,
                                              const Tracked* tracked) {
    next_ = params_.next_scan ? next : nullptr;
    tracked_ = tracked;
    Result res;
    try {
        res = filter(scan, out);
    } catch (...) {
        next_ = nullptr;
        tracked_ = nullptr;
        throw;
    }
    next_ = nullptr;
    tracked_ = nullptr;
    return res;
}

EvidenceFilter::Result EvidenceFilter::filter(Scan& scan, Clusters& out) {
    Result res;
    const std::size_t n = scan.range.size();
    toPoints(scan);
    // 1.-2. Noise, lines and segments.
    const double sigma = estimateSigma(scan);
    res.sigma = sigma;
    res.sigma_measured = params_.sigma_m > 0.0 ? 0.0 : std::max(0.0, measured_smoothed_);
    segment(scan, sigma, out);
    res.segments = out.count();
    spike_candidates_.clear();
    if (params_.spikes) findSpikeCandidates(scan, sigma);

    // 3. Temporal evidence from the last two keyframes.
    evidence_.assign(n, kUnknown);
    res.temporal = temporalEvidence(scan, out, sigma, res, true);

    // 4. Segments: small and unsupported, or mostly in free space.
    const std::size_t valid_in = scan.countValid();
    const auto cap = static_cast<std::size_t>(
        std::floor(params_.max_removed_fraction * static_cast<double>(valid_in)));
    res.removal_wanted = markNoise(out, res.temporal);
    // 5. Bounded removal.
    const bool temporal = boundRemoval(scan, out, sigma, valid_in, cap, res);
    for (std::size_t c = 0; c < out.count(); ++c) res.small_segments += out.noise[c] & small_[c];
    // The previous keyframe for the next scan keeps every return (removed ones too: a thin
    // object removed once as unsupported must still support the next view).
    keepAsReference(scan);  // swaps evidence_, x_, y_, link_ away: use the reference's below
    if (!raw_.empty() && params_.temporal) keepRaw(scan, tracked_);  // before removal: the raw scan
    const std::vector<std::uint8_t>& kept_ev = refs_[0].present ? refs_[0].evidence : evidence_;
    removeMarked(scan, out, kept_ev, temporal, sigma, valid_in, cap, res);
    return res;
}

void EvidenceFilter::toPoints(const Scan& scan) {
    const std::size_t n = scan.range.size();
    ScanGeometry geom = scan.geometry;
    geom.beams = n;  // tables follow the data
    updateTables(geom);
    x_.resize(n);
    y_.resize(n);
    const float* range = scan.range.data();
    const float* cs = dirs_.cos.data();
    const float* sn = dirs_.sin.data();
    float* x = x_.data();
    float* y = y_.data();
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) {
        x[i] = range[i] * cs[i];
        y[i] = range[i] * sn[i];
    }
}

bool EvidenceFilter::boundRemoval(const Scan& scan, Clusters& out, double sigma,
                                  std::size_t valid_in, std::size_t cap, Result& res) {
    // More than the bound disagrees with the references: they are stale. With the raw scan
    // just before, first the keyframes alone (what temporal_scans = 0 does).
    bool temporal = res.temporal;
    std::size_t wanted = res.removal_wanted;
    if (wanted > cap && temporal && res.recent && confirmedByRecent(out, valid_in, wanted)) {
        res.confirmed = true;  // a burst the raw scan just before saw through: removed whole
        wanted = 0;
    }
    if (wanted > cap && temporal && res.recent) {
        Result kf;
        evidence_.assign(scan.range.size(), kUnknown);
        temporal = temporalEvidence(scan, out, sigma, kf, false);
        res.free_points = kf.free_points;
        res.supported = kf.supported;
        res.tracked = kf.tracked;
        res.recent_overruled = true;
        wanted = markNoise(out, temporal);
    }
    if (wanted > cap && temporal) {
        res.stale_references = true;
        temporal = false;
        if (markNoise(out, false) > cap) {
            capNoise(out, cap);
            res.capped = true;
        }
    } else if (wanted > cap) {
        capNoise(out, cap);
        res.capped = true;
    }
    return temporal;
}

void EvidenceFilter::removeMarked(Scan& scan, const Clusters& out,
                                  const std::vector<std::uint8_t>& kept_ev, bool temporal,
                                  double sigma, std::size_t valid_in, std::size_t cap,
                                  Result& res) {
    const std::size_t n = scan.range.size();
    // Free returns go unless they lie on a line with their neighbours (a surface the previous
    // keyframe saw a little farther: pose error, a door that moved); every return of a removed
    // segment goes.
    // Branch-free: the noise flag looked up by label + 1 (0: no return, never noise).
    noise_by_label_.resize(out.count() + 1);
    noise_by_label_[0] = 0;
    std::copy(out.noise.begin(), out.noise.end(), noise_by_label_.begin() + 1);
    remove_.resize(n);
    {
        const std::uint8_t* noise = noise_by_label_.data();
        const std::int32_t* label = out.label.data();
        const std::uint8_t* ev = kept_ev.data();
        const std::uint8_t* line = line_.data();
        // Evidence is only ever set for returns in a segment: no free return without a label.
        const auto free_counts = static_cast<std::uint8_t>(temporal);
        std::uint8_t* remove = remove_.data();
        for (std::size_t i = 0; i < n; ++i)
            remove[i] = static_cast<std::uint8_t>(
                noise[label[i] + 1] | (free_counts & (ev[i] == kFree) & (line[i] == 0)));
    }
    // 4b. Spikes; 6. mixed pixels; 7. surfaces kept.
    if (params_.spikes) res.spikes = markSpikes(scan, kept_ev, temporal, cap);
    if (params_.veil) res.veils = markVeils(scan, out, sigma, cap);
    if (params_.keep_surfaces) {
        SurfaceRunParams sp;
        sp.min_beams = params_.surface_min_beams;
        // At the scan's noise, and never stricter than what the summary calls a surface.
        sp.tolerance_m = std::max(params_.surface_sigmas * sigma, SurfaceRunParams{}.tolerance_m);
        res.surface_kept = spareSurfaceRuns(scan, remove_.data(), sp);
    }
    {
        const std::uint8_t* remove = remove_.data();
        std::uint8_t* valid = scan.valid.data();
#pragma omp simd
        for (std::size_t i = 0; i < n; ++i) valid[i] = remove[i] ? 0 : valid[i];
    }
    res.points_removed += valid_in - scan.countValid();  // nothing changed valid since step 4
}

void EvidenceFilter::findSpikeCandidates(const Scan& scan, double sigma) {
    // A return nearer or farther than both neighbours by more than the pair margin, where the
    // neighbours are one surface across it (step 2's breakpoint test over two beams): a beam
    // off the surface its neighbours agree on, off a line.
    const std::size_t n = scan.range.size();
    const Breakpoints bp = breakpoints(sigma);
    const float m = bp.noise;
    const float factor2 = bp.factor[std::min<std::size_t>(2, bp.max_step)];
    const float cos2 = std::cos(2.0f * res_);
    const float* r = scan.range.data();
    const std::uint8_t* v = scan.valid.data();
    spike_candidates_.clear();
    spike_margin_ = m;
    if (n < 3) return;
    // Branch-free: off both neighbours' ranges (most beams lie between them).
    off_.resize(n);  // beams 1 .. n - 2 written and read below
    std::uint8_t* off = off_.data();
#pragma omp simd
    for (std::size_t i = 1; i < n - 1; ++i) {
        const float lo = std::min(r[i - 1], r[i + 1]), hi = std::max(r[i - 1], r[i + 1]);
        off[i] = static_cast<std::uint8_t>((r[i] < lo - m) | (r[i] > hi + m));
    }
    // The few candidates among beams 1 .. n - 2.
    for (std::size_t i = Scan::nextNonZero(off, 1, n - 1); i + 1 < n;
         i = Scan::nextNonZero(off, i + 1, n - 1)) {
        const float a = r[i - 1], b = r[i + 1];
        if (!v[i - 1] || !v[i] || !v[i + 1] || line_[i]) continue;
        const float dmax = std::min(a, b) * factor2 + m;
        if (a * a + b * b - 2.0f * a * b * cos2 > dmax * dmax) continue;  // not one surface
        spike_candidates_.push_back(static_cast<std::uint32_t>(i));
    }
}

void EvidenceFilter::markObjectSupport(const Projection& pr) {
    if (!pr.usable || !params_.spike_object_support) return;
    for (std::size_t j = 0; j < spike_candidates_.size(); ++j) {
        // Only the supported ones: a reference that did not support a return (no return of
        // it within the margin) cannot have seen an object there either.
        const std::uint32_t i = spike_candidates_[j];
        if (evidence_[i] != kSupported || object_support_[j]) continue;
        const float qx = pr.c * x_[i] - pr.s * y_[i] + pr.tx;
        const float qy = pr.s * x_[i] + pr.c * y_[i] + pr.ty;
        if (objectSupported(pr, qx, qy, (fastAtan2(qy, qx) - first_) * inv_step_))
            object_support_[j] = 1;
    }
}

bool EvidenceFilter::objectSupported(const Projection& pr, float qx, float qy, float u) const {
    // classifyAt's support by a return, restricted to returns that are not inside a smooth
    // surface of the reference.
    const Reference& ref = *pr.ref;
    const std::size_t rn = ref.range.size();
    if (!(u >= 0.0f) || !(u < static_cast<float>(rn - 1))) return false;
    const std::size_t k0 = static_cast<std::size_t>(u), k1 = k0 + 1;
    const float rho = std::sqrt(qx * qx + qy * qy);
    const float m = pr.m0 + pr.m1 * rho + rho * res_;
    const std::size_t lo = k0 > 0 ? k0 - 1 : 0, hi = std::min(rn - 1, k1 + 1);
    const float* range = ref.range.data();
    const std::uint8_t* valid = ref.valid.data();
    for (std::size_t k = lo; k <= hi; ++k) {
        if (!valid[k]) continue;
        const float dx = qx - ref.x[k], dy = qy - ref.y[k];
        if (dx * dx + dy * dy > m * m) continue;
        const bool smooth = k > 0 && k + 1 < rn && valid[k - 1] && valid[k + 1] &&
                            std::abs(range[k] - range[k - 1]) <= spike_margin_ &&
                            std::abs(range[k] - range[k + 1]) <= spike_margin_;
        if (!smooth) return true;
    }
    return false;
}

std::size_t EvidenceFilter::markSpikes(const Scan& scan, const std::vector<std::uint8_t>& kept_ev,
                                       bool temporal, std::size_t cap) {
    // Step 4b: the candidates (findSpikeCandidates) that step 4 left and no reference supports
    // (with spike_object_support: where no reference saw an object).
    spikes_.clear();
    for (std::size_t j = 0; j < spike_candidates_.size(); ++j) {
        const std::uint32_t i = spike_candidates_[j];
        if (remove_[i]) continue;
        if (temporal && kept_ev[i] == kSupported &&
            (!params_.spike_object_support || object_support_[j]))
            continue;
        spikes_.push_back(i);
    }
    if (spikes_.empty()) return 0;
    // Within what the bound leaves (step 5): more is clutter (a railing, foliage), not spikes.
    if (spikes_.size() > roomUnderBound(scan, cap)) return 0;
    for (const std::uint32_t i : spikes_) remove_[i] = 1;
    return spikes_.size();
}

std::size_t EvidenceFilter::roomUnderBound(const Scan& scan, std::size_t cap) const {
    const std::size_t n = std::min(scan.valid.size(), remove_.size());
    const std::uint8_t* v = scan.valid.data();
    const std::uint8_t* remove = remove_.data();
    std::size_t removed = 0;
    for (std::size_t i = 0; i < n; ++i) removed += remove[i] & v[i];
    return removed < cap ? cap - removed : 0;
}

std::size_t EvidenceFilter::markVeils(const Scan& scan, const Clusters& out, double sigma,
                                      std::size_t cap) {
    const std::size_t n = scan.range.size(), count = out.count();
    seg_first_.assign(count, static_cast<std::uint32_t>(n));
    seg_last_.assign(count, 0);
    for (std::size_t i = 0; i < n; ++i) {
        if (out.label[i] < 0) continue;
        const auto c = static_cast<std::size_t>(out.label[i]);
        seg_first_[c] = std::min<std::uint32_t>(seg_first_[c], static_cast<std::uint32_t>(i));
        seg_last_[c] = static_cast<std::uint32_t>(i);
    }
    veil_.assign(n, 0);
    const float margin = static_cast<float>(pairMargin(sigma));
    for (std::size_t c = 0; c < count; ++c) {
        const std::size_t a = seg_first_[c], b = seg_last_[c];
        if (a >= n) continue;
        const std::size_t pa = neighbourReturn(scan, a, false), nb = neighbourReturn(scan, b, true);
        if (out.size[c] <= params_.max_small_points && pa < n && nb < n &&
            out.label[pa] != out.label[a] && out.label[nb] != out.label[b]) {
            // A small segment between a nearer and a farther surface.
            const float near = std::min(scan.range[pa], scan.range[nb]) + margin;
            const float far = std::max(scan.range[pa], scan.range[nb]) - margin;
            bool between = near < far;
            for (std::size_t i = a; i <= b && between; ++i)
                between =
                    out.label[i] != out.label[a] || (scan.range[i] > near && scan.range[i] < far);
            if (between) {
                for (std::size_t i = a; i <= b; ++i) veil_[i] = out.label[i] == out.label[a];
                continue;
            }
        }
        veilAtEnd(scan, out, a, false, sigma);
        veilAtEnd(scan, out, b, true, sigma);
    }
    veilRuns(scan, sigma);
    std::size_t marked = 0;
    for (std::size_t i = 0; i < n; ++i) marked += veil_[i] && !remove_[i];
    // Within what the bound leaves (step 5, after steps 4 and 4b): more is clutter or
    // vegetation, not a few edges: no guess.
    if (marked > roomUnderBound(scan, cap)) return 0;
    for (std::size_t i = 0; i < n; ++i) remove_[i] |= veil_[i];
    return marked;
}

void EvidenceFilter::veilRuns(const Scan& scan, double sigma) {
    // Runs of 1-3 consecutive returns at one depth strictly between their two neighbours' (one
    // nearer, one farther), off the line at both ends, with a step along the ray on both sides.
    const std::size_t n = scan.range.size();
    const float m = static_cast<float>(pairMargin(sigma));
    const float along = static_cast<float>(0.5 * std::sin(res_) / std::tan(lambda_));
    const float* r = scan.range.data();
    const std::uint8_t* v = scan.valid.data();
    for (std::size_t i = 1; i + 1 < n; ++i) {
        if (!v[i - 1] || !v[i] || line_[i]) continue;
        for (std::size_t len = 1; len <= std::min<std::size_t>(3, params_.max_small_points);
             ++len) {
            const std::size_t b = i + len;
            if (b >= n || !v[b - 1] || !v[b]) break;
            float lo = r[i], hi = r[i];
            for (std::size_t k = i; k < b; ++k) lo = std::min(lo, r[k]), hi = std::max(hi, r[k]);
            if (hi - lo > 2.0f * m) break;
            const float near = std::min(r[i - 1], r[b]), far = std::max(r[i - 1], r[b]);
            const float step = std::max(2.0f * m, along * lo);
            if (lo - near < step || far - hi < step || line_[b - 1]) continue;
            for (std::size_t k = i; k < b; ++k) veil_[k] = 1;
            break;
        }
    }
}

std::size_t EvidenceFilter::neighbourReturn(const Scan& scan, std::size_t i, bool after) const {
    const std::size_t n = scan.range.size();
    for (std::size_t k = 1; k <= params_.max_gap_beams + 1; ++k) {
        if (after ? i + k >= n : k > i) break;
        const std::size_t j = after ? i + k : i - k;
        if (scan.valid[j]) return j;
    }
    return n;
}

void EvidenceFilter::veilAtEnd(const Scan& scan, const Clusters& out, std::size_t end, bool last,
                               double sigma) {
    // The end's returns, walking inward: end, then its neighbours in the same segment.
    const std::size_t n = scan.range.size();
    const std::size_t f = neighbourReturn(scan, end, last);  // across the edge
    if (f >= n || out.label[f] == out.label[end]) return;
    const std::size_t most = params_.max_small_points;
    std::size_t run[kMaxVeil + 2];
    std::size_t have = 0;
    for (std::size_t i = end; have < std::min(most, kMaxVeil) + 2;) {
        run[have++] = i;
        const std::size_t j = neighbourReturn(scan, i, !last);
        if (j >= n || out.label[j] != out.label[end]) break;
        i = j;
    }
    const float tol = static_cast<float>(3.0 * kResidualScale * sigma);
    const float rf = scan.range[f];
    // The longest end run of L returns that all leave the line through the two returns inside
    // them toward the other side of the edge, and lie between that line and the other side.
    for (std::size_t len = std::min(most, have >= 2 ? have - 2 : 0); len >= 1; --len) {
        const std::size_t i1 = run[len], i2 = run[len + 1];
        const float x1 = scan.range[i1] * dirs_.cos[i1], y1 = scan.range[i1] * dirs_.sin[i1];
        const float dx = x1 - scan.range[i2] * dirs_.cos[i2];
        const float dy = y1 - scan.range[i2] * dirs_.sin[i2];
        bool veil = true;
        for (std::size_t k = 0; k < len && veil; ++k) {
            const std::size_t j = run[k];
            const float cj = dirs_.cos[j], sj = dirs_.sin[j];
            const float den = cj * dy - sj * dx;  // the ray crossing the line
            if (std::abs(den) < 1e-6f) {
                veil = false;
                break;
            }
            const float pred = (x1 * dy - y1 * dx) / den;
            const float rj = scan.range[j], e = rj - pred;
            const bool toward = (rf > pred) ? (e > tol && rj < rf) : (e < -tol && rj > rf);
            veil = pred > 0.0f && toward;
        }
        if (!veil) continue;
        for (std::size_t k = 0; k < len; ++k) veil_[run[k]] = 1;
        return;
    }
}

bool EvidenceFilter::confirmedByRecent(const Clusters& out, std::size_t valid_in,
                                       std::size_t wanted) const {
    if (recent_ev_.size() != out.label.size()) return false;
    if (static_cast<double>(wanted) >
        params_.max_confirmed_fraction * static_cast<double>(valid_in))
        return false;
    // The rest of the scan, as the raw scan just before saw it: a good alignment supports the
    // surfaces outside the removed segments; stale references or a wrong alignment leave free
    // returns scattered over them.
    std::size_t supported = 0, free = 0;
    for (std::size_t i = 0; i < out.label.size(); ++i) {
        if (out.label[i] < 0 || out.noise[static_cast<std::size_t>(out.label[i])]) continue;
        supported += recent_ev_[i] == kSupported;
        free += recent_ev_[i] == kFree;
    }
    const std::size_t judged = supported + free;
    return judged >= kMinConfirmJudged &&
           static_cast<double>(supported) >= params_.confirm_support * static_cast<double>(judged);
}

std::size_t EvidenceFilter::markNoise(Clusters& out, bool temporal) {
    small_.resize(out.count());
    for (std::size_t c = 0; c < out.count(); ++c) {
        const double r = std::max(0.05, static_cast<double>(out.mean_range[c]));
        const double need = res_ > 0.0f ? std::ceil(params_.min_object_size_m / (r * res_)) : 1.0;
        const auto bar = static_cast<std::size_t>(
            std::min(static_cast<double>(params_.max_small_points) + 1.0, std::max(2.0, need)));
        const bool fragment = params_.dropout_fragments && out.size[c] >= 2 && !flanked_[c];
        const bool small = out.size[c] < bar && !fragment;
        const bool supported = temporal && supported_in_[c] > 0;
        const bool free = temporal && classified_in_[c] > 0 && 2 * free_in_[c] >= classified_in_[c];
        out.noise[c] = (small && !supported) || free ? 1 : 0;
        small_[c] = small ? 1 : 0;
    }
    // Every return of a noise segment, and the free returns off a line of the others (counted
    // per segment as they were judged: evidence is never set free after that).
    std::size_t removed = 0;
    for (std::size_t c = 0; c < out.count(); ++c)
        removed += out.noise[c] ? out.size[c] : temporal ? free_off_line_in_[c] : 0u;
    return removed;
}

void EvidenceFilter::capNoise(Clusters& out, std::size_t cap) {
    order_.clear();
    for (std::size_t c = 0; c < out.count(); ++c)
        if (out.noise[c]) order_.push_back(static_cast<std::uint32_t>(c));
    // Smallest first; among equals the nearest: a real object near the sensor spans more beams
    // than one far away, so a lone return near it is the less likely object (and the spikes
    // near the sensor are the ones a capped scan would otherwise keep).
    std::sort(order_.begin(), order_.end(), [&](std::uint32_t a, std::uint32_t b) {
        return out.size[a] != out.size[b] ? out.size[a] < out.size[b]
                                          : out.mean_range[a] < out.mean_range[b];
    });
    std::size_t removed = 0;
    for (const std::uint32_t c : order_) {
        if (removed + out.size[c] <= cap)
            removed += out.size[c];
        else
            out.noise[c] = 0;
    }
}

}  // namespace kfd
