// Parameter helper: the paper's Formulas 4-5 (Sec. 3.1.4, "Select Parameters").
#pragma once

#include <cstddef>
#include <string>

#include "kfd/pipeline/error.h"

namespace kfd {

/// Window suggestion from robot speed and scan rate.
struct WindowSuggestion {
    double dx_cm = 0.0;           // Formula 4: distance travelled between scans, dx = V/f (cm)
    std::size_t m = 1;            // suggested window size
    std::size_t m_min = 0;        // smallest integer m with 18 < m*dx^2 < 30 (0 = none)
    std::size_t m_max = 0;        // largest such m (0 = none)
    bool rule_satisfied = false;  // whether `m` satisfies Formula 5
    double p_threshold = 0.0;     // P_pair^m
    std::string note;             // what was done when the rule cannot be met
};

struct WindowHelperParams {
    double lower = 18.0;          // Formula 5 lower bound on m*dx^2 (cm^2), exclusive
    double upper = 30.0;          // Formula 5 upper bound on m*dx^2 (cm^2), exclusive
    std::size_t max_window = 64;  // never suggest more keyframes than this
};

/// Suggests m from speed V (m/s) and scan rate f (Hz) with Formula 4 (dx = V/f, in cm) and
/// Formula 5 (18 < m*dx^2 < 30). When several integers fit, the smallest is suggested: every
/// reference costs one correlation per scan, and the paper's own picks (m=8 at 0.752 m/s,
/// m=9 at 0.575 m/s, f=40 Hz) both lie in the allowed ranges (6..8 and 9..14).
///
/// When no integer fits:
///  - dx^2 >= upper (fast robot or slow scanner, e.g. 5 Hz logs with dx ~ 10-20 cm): m = 1,
///    each scan is compared with the last keyframe only; `note` says so.
///  - the allowed range lies above max_window (robot almost still): m = max_window.
/// Throws kfd::ParameterError for non-positive speed/rate or p_pair outside (0, 1].
WindowSuggestion suggestWindow(double speed_mps, double rate_hz, double p_pair,
                               const WindowHelperParams& p = {});

}  // namespace kfd
