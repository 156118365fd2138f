// Similarity of two scan histograms: Formula 2 (Sec. 3.1.3, Pearson correlation).
#pragma once

#include <cstddef>

namespace kfd {

/// Pearson correlation coefficient of a[0..n) and b[0..n) (Formula 2), in [-1, 1].
///
/// Zero-variance rules (Formula 2 divides by zero there):
///  - both histograms constant and equal (within `tolerance`, relative to their magnitude) -> 1
///    (the scans are indistinguishable);
///  - otherwise, if either is constant -> 0 (no linear relation can be claimed).
/// n == 0 -> 0.
double pearson(const double* a, const double* b, std::size_t n, double tolerance = 1e-9);

/// The similarity the keyframe selector multiplies (Formula 3): Pearson clamped to [0, 1].
/// A negative correlation means "dissimilar", never "similar": clamping stops two negative
/// factors from multiplying into a positive P_common.
inline double similarity(const double* a, const double* b, std::size_t n) {
    const double r = pearson(a, b, n);
    return r > 0.0 ? r : 0.0;
}

}  // namespace kfd
