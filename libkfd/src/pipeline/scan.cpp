#include "kfd/pipeline/scan.h"

#include <algorithm>
#include <cstdint>
#include <cstring>

namespace kfd {
namespace {
constexpr std::size_t kBlock = std::size_t{1} << 30;
}  // namespace

std::size_t Scan::countNonZero(const std::uint8_t* p, std::size_t n) {
    std::size_t count = 0;
    // In blocks whose count fits 32 bits, so that the loop vectorises with 32-bit lanes.
    for (std::size_t start = 0; start < n; start += kBlock) {
        const std::size_t end = std::min(n, start + kBlock);
        std::uint32_t c = 0;
#pragma omp simd reduction(+ : c)
        for (std::size_t i = start; i < end; ++i) c += p[i] != 0;
        count += c;
    }
    return count;
}

std::size_t Scan::nextNonZero(const std::uint8_t* p, std::size_t i, std::size_t n) {
    for (; i + 8 <= n; i += 8) {
        std::uint64_t word = 0;
        std::memcpy(&word, p + i, sizeof word);
        if (word != 0) break;
    }
    while (i < n && p[i] == 0) ++i;
    return i;
}

}  // namespace kfd
