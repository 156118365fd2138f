#include "kfd/paper/window_helper.h"

#include <cmath>
#include <cstdio>
#include "kfd/pipeline/error.h"

namespace kfd {

WindowSuggestion suggestWindow(double speed_mps, double rate_hz, double p_pair,
                               const WindowHelperParams& p) {
    if (!(speed_mps > 0.0) || !std::isfinite(speed_mps))
        throw ParameterError("speed", "speed must be > 0 m/s");
    if (!(rate_hz > 0.0) || !std::isfinite(rate_hz))
        throw ParameterError("rate", "scan rate must be > 0 Hz");
    if (!(p_pair > 0.0 && p_pair <= 1.0))
        throw ParameterError("p_pair", "p_pair must be in (0, 1]");
    if (!(p.lower >= 0.0 && p.upper > p.lower) || p.max_window < 1)
        throw ParameterError("bounds", "invalid Formula 5 bounds");

    WindowSuggestion s;
    s.dx_cm = 100.0 * speed_mps / rate_hz;  // Formula 4
    const double dx2 = s.dx_cm * s.dx_cm;
    // Integers m with lower < m*dx2 < upper (Formula 5).
    std::size_t lo = static_cast<std::size_t>(std::floor(p.lower / dx2)) + 1;
    const double hi_real = p.upper / dx2;
    std::size_t hi = static_cast<std::size_t>(std::ceil(hi_real)) - 1;
    if (lo < 1) lo = 1;
    if (hi_real > 1e9) hi = p.max_window;  // dx ~ 0
    if (lo <= hi) {
        s.m_min = lo;
        s.m_max = hi;
    }
    if (s.m_min != 0 && s.m_min <= p.max_window) {
        s.m = s.m_min;
        s.rule_satisfied = true;
    } else if (s.m_min != 0) {
        s.m = p.max_window;
        s.note = "the robot barely moves between scans: Formula 5 asks for m >= " +
                 std::to_string(s.m_min) + "; capped at " + std::to_string(p.max_window);
    } else if (dx2 >= p.upper) {
        s.m = 1;
        char dx[32];
        std::snprintf(dx, sizeof(dx), "%.1f", s.dx_cm);
        s.note = std::string("scans are ") + dx +
                 " cm apart, so no window satisfies 18 < m*dx^2 < 30; using m = 1 (compare with "
                 "the last keyframe only)";
    } else {
        // No integer falls strictly between the bounds: take the nearest one to the interval.
        s.m = static_cast<std::size_t>(std::lround(0.5 * (p.lower + p.upper) / dx2));
        if (s.m < 1) s.m = 1;
        if (s.m > p.max_window) s.m = p.max_window;
        s.note =
            "no integer m gives 18 < m*dx^2 < 30; using the closest, m = " + std::to_string(s.m);
    }
    s.p_threshold = std::pow(p_pair, static_cast<double>(s.m));
    return s;
}

}  // namespace kfd
