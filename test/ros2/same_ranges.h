// The live tests' comparison of a scan kfd_ros2 published with the one kfd-filter kept offline.
#pragma once

#include <cmath>
#include <vector>

namespace kfd_test {

/// Equal beam for beam, NaN equal to NaN (a removed point), any other value exactly.
inline bool sameRanges(const std::vector<float>& a, const std::vector<float>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (std::isnan(a[i]) != std::isnan(b[i]) || (!std::isnan(a[i]) && a[i] != b[i]))
            return false;
    return true;
}

}  // namespace kfd_test
