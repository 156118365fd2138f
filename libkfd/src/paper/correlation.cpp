#include "kfd/paper/correlation.h"

#include <algorithm>
#include <cmath>

namespace kfd {

double pearson(const double* a, const double* b, std::size_t n, double tolerance) {
    if (n == 0) return 0.0;
    double ma = 0.0, mb = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        ma += a[i];
        mb += b[i];
    }
    ma /= static_cast<double>(n);
    mb /= static_cast<double>(n);
    double sab = 0.0, saa = 0.0, sbb = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        const double da = a[i] - ma, db = b[i] - mb;
        sab += da * db;
        saa += da * da;
        sbb += db * db;
    }
    const double scale = std::max({1.0, std::abs(ma), std::abs(mb)});
    const double eps = tolerance * scale;
    const bool const_a = std::sqrt(saa / static_cast<double>(n)) <= eps;
    const bool const_b = std::sqrt(sbb / static_cast<double>(n)) <= eps;
    if (const_a || const_b) {
        return (const_a && const_b && std::abs(ma - mb) <= eps) ? 1.0 : 0.0;
    }
    const double r = sab / std::sqrt(saa * sbb);
    return std::clamp(r, -1.0, 1.0);  // guard against rounding just outside [-1, 1]
}

}  // namespace kfd
