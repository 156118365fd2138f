#include "kfd/algorithms/surface_run.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace kfd {
namespace {

// Running sums of a run's points, for a total-least-squares line fit in one pass.
struct LineSums {
    std::size_t n = 0;
    double x = 0, y = 0, xx = 0, yy = 0, xy = 0, range = 0;
    void add(double px, double py, double r) {
        ++n;
        x += px;
        y += py;
        xx += px * px;
        yy += py * py;
        xy += px * py;
        range += r;
    }
};

// Whether the run of beams [first, last] (its removed returns summed in `s`; `removed(i)`: beam
// i's return is removed) looks like a surface; fills `out` when it does.
template <class Removed>
bool looksLikeSurface(const Scan& scan, Removed removed, std::size_t first, std::size_t last,
                      const LineSums& s, const SurfaceRunParams& p, SurfaceRun& out) {
    if (s.n < p.min_beams) return false;
    const double n = static_cast<double>(s.n);
    const double mx = s.x / n, my = s.y / n;
    const double cxx = s.xx / n - mx * mx, cyy = s.yy / n - my * my, cxy = s.xy / n - mx * my;
    // Eigenvalues of the covariance: the smaller is the mean squared distance to the line.
    const double half_trace = 0.5 * (cxx + cyy);
    const double root = std::sqrt(std::max(0.0, 0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy));
    const double small = std::max(0.0, half_trace - root);
    const double rms = std::sqrt(small);
    if (rms > std::max(p.tolerance_m, p.tolerance_ratio * s.range / n)) return false;
    // The line's direction, and the extent of the points along it.
    const double angle = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
    const double ux = std::cos(angle), uy = std::sin(angle);
    double lo = 0.0, hi = 0.0, px = 0.0, py = 0.0;
    bool any = false;
    for (std::size_t i = first; i <= last; ++i) {
        if (!removed(i)) continue;
        const double a = scan.geometry.angle(i), r = scan.range[i];
        const double x = r * std::cos(a), y = r * std::sin(a);
        if (any) {  // neighbours close enough to be one surface
            const double gap = std::hypot(x - px, y - py);
            if (gap > p.max_gap_beams * std::max(r, 0.05) * scan.geometry.resolution() + 0.01)
                return false;
        }
        const double t = (x - mx) * ux + (y - my) * uy;
        lo = any ? std::min(lo, t) : t;
        hi = any ? std::max(hi, t) : t;
        px = x;
        py = y;
        any = true;
    }
    if (hi - lo < p.min_length_m) return false;
    out = {first, s.n, hi - lo, rms};
    return true;
}

// Calls `found(run)` for every run of removed returns that looks like a surface. A run: beams
// whose return is removed (`removed(i)`), up to a beam whose return stays (`kept(i)`); beams
// with no return (neither) do not break it. Between runs, `skip(i)` jumps to a beam at or after
// i that may be removed (every beam before it is not).
template <class Removed, class Kept, class Skip, class Found>
void forEachSurfaceRun(const Scan& scan, Removed removed, Kept kept, Skip skip,
                       const SurfaceRunParams& p, Found found) {
    const std::size_t n = std::min(scan.valid.size(), scan.range.size());
    std::size_t first = 0, last = 0;
    LineSums s;
    auto close = [&] {  // most beams close an empty run: nothing to reset then
        if (s.n == 0) return;
        SurfaceRun r;
        if (looksLikeSurface(scan, removed, first, last, s, p, r)) found(r, last);
        s = LineSums{};
    };
    for (std::size_t i = 0; i < n; ++i) {
        if (s.n == 0 && (i = skip(i)) >= n) break;  // no run open: on to the next removed return
        if (kept(i)) {
            close();
            continue;
        }
        if (!removed(i)) continue;  // no return: does not break a run
        if (s.n == 0) first = i;
        last = i;
        const double a = scan.geometry.angle(i), r = scan.range[i];
        s.add(r * std::cos(a), r * std::sin(a), r);
    }
    close();
}

}  // namespace

SurfaceRun longestRemovedSurface(const Scan& scan, const std::uint8_t* before,
                                 const SurfaceRunParams& p) {
    SurfaceRun best;
    forEachSurfaceRun(
        scan, [&](std::size_t i) { return before[i] && !scan.valid[i]; },
        [&](std::size_t i) { return before[i] && scan.valid[i]; }, [](std::size_t i) { return i; },
        p,
        [&](const SurfaceRun& r, std::size_t) {
            if (r.length_m > best.length_m) best = r;
        });
    return best;
}

std::size_t spareSurfaceRuns(const Scan& scan, std::uint8_t* remove, const SurfaceRunParams& p) {
    const std::size_t n = std::min(scan.valid.size(), scan.range.size());
    std::size_t spared = 0;
    forEachSurfaceRun(
        scan, [&](std::size_t i) { return scan.valid[i] && remove[i]; },
        [&](std::size_t i) { return scan.valid[i] && !remove[i]; },
        [&](std::size_t i) { return Scan::nextNonZero(remove, i, n); }, p,
        [&](const SurfaceRun& r, std::size_t last) {
            for (std::size_t i = r.first; i <= last; ++i)
                if (scan.valid[i] && remove[i]) {
                    remove[i] = 0;
                    ++spared;
                }
        });
    return spared;
}

}  // namespace kfd
