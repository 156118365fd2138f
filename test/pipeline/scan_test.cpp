// Scan's byte helpers against plain loops, over random flags of every length up to a few words.
#include "kfd/pipeline/scan.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

namespace {

std::size_t plainNextNonZero(const std::vector<std::uint8_t>& p, std::size_t i, std::size_t n) {
    while (i < n && p[i] == 0) ++i;
    return i;
}

// Sparse flags with any non-zero value, as the denoiser's removal flags are.
std::vector<std::uint8_t> randomFlags(std::mt19937& rng, std::size_t n, double density) {
    std::bernoulli_distribution set(density);
    std::uniform_int_distribution<int> value(1, 255);
    std::vector<std::uint8_t> p(n);
    for (auto& b : p) b = set(rng) ? static_cast<std::uint8_t>(value(rng)) : 0;
    return p;
}

}  // namespace

TEST(Scan, NextNonZeroFindsTheFirstSetByteFromAnyStartLikeAPlainLoop) {
    std::mt19937 rng(7);
    for (int trial = 0; trial < 400; ++trial) {
        const std::size_t n = static_cast<std::size_t>(trial % 41);
        const auto p = randomFlags(rng, n, trial % 3 == 0 ? 0.02 : 0.2);
        for (std::size_t i = 0; i <= n; ++i)
            for (std::size_t end = i; end <= n; ++end)
                ASSERT_EQ(kfd::Scan::nextNonZero(p.data(), i, end), plainNextNonZero(p, i, end))
                    << "n " << n << " from " << i << " to " << end;
    }
}

TEST(Scan, NextNonZeroReturnsTheEndWhenEveryByteIsZero) {
    const std::vector<std::uint8_t> zeros(1081, 0);
    EXPECT_EQ(kfd::Scan::nextNonZero(zeros.data(), 0, zeros.size()), zeros.size());
    EXPECT_EQ(kfd::Scan::nextNonZero(zeros.data(), 5, 17), 17u);
}

TEST(Scan, CountNonZeroCountsEveryNonZeroValueLikeAPlainLoop) {
    std::mt19937 rng(11);
    for (std::size_t n : {0u, 1u, 7u, 8u, 9u, 63u, 64u, 65u, 1081u}) {
        const auto p = randomFlags(rng, n, 0.5);
        std::size_t plain = 0;
        for (const std::uint8_t b : p) plain += b != 0;
        EXPECT_EQ(kfd::Scan::countNonZero(p.data(), p.size()), plain) << "n " << n;
    }
}
