#include "kfd/paper/correlation.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace kfd {
namespace {

double pearsonOf(const std::vector<double>& a, const std::vector<double>& b) {
    EXPECT_EQ(a.size(), b.size());
    return pearson(a.data(), b.data(), a.size());
}

double similarityOf(const std::vector<double>& a, const std::vector<double>& b) {
    return similarity(a.data(), b.data(), a.size());
}

/// Textbook two-pass Pearson coefficient (Formula 2), in long double.
double referencePearson(const std::vector<double>& a, const std::vector<double>& b) {
    const std::size_t n = a.size();
    long double ma = 0, mb = 0;
    for (std::size_t i = 0; i < n; ++i) {
        ma += a[i];
        mb += b[i];
    }
    ma /= n;
    mb /= n;
    long double num = 0, va = 0, vb = 0;
    for (std::size_t i = 0; i < n; ++i) {
        num += (a[i] - ma) * (b[i] - mb);
        va += (a[i] - ma) * (a[i] - ma);
        vb += (b[i] - mb) * (b[i] - mb);
    }
    return static_cast<double>(num / std::sqrt(va * vb));
}

TEST(Pearson, PerfectlyCorrelated) {
    EXPECT_NEAR(pearsonOf({1, 2, 3, 4}, {1, 2, 3, 4}), 1.0, 1e-12);
    // Invariant to offset and positive scale: ranges of the same scene from closer by.
    EXPECT_NEAR(pearsonOf({1, 2, 3, 4}, {5, 7, 9, 11}), 1.0, 1e-12);
}

TEST(Pearson, AntiCorrelated) {
    EXPECT_NEAR(pearsonOf({1, 2, 3, 4}, {4, 3, 2, 1}), -1.0, 1e-12);
    EXPECT_NEAR(pearsonOf({1, 2, 3}, {10, 8, 6}), -1.0, 1e-12);
}

TEST(Pearson, HandComputedCase) {
    // a - mean = (-1, 0, 1), b - mean = (-1, 1, 0): sum ab = 1, sum aa = sum bb = 2 -> 0.5.
    EXPECT_NEAR(pearsonOf({1, 2, 3}, {1, 3, 2}), 0.5, 1e-12);
    // a - mean = (-1.5, -0.5, 0.5, 1.5), b - mean = (-1, 1, -1, 1):
    // sum ab = 1.5 - 0.5 - 0.5 + 1.5 = 2, sum aa = 5, sum bb = 4 -> 2 / sqrt(20).
    EXPECT_NEAR(pearsonOf({1, 2, 3, 4}, {0, 2, 0, 2}), 0.4472135954999579, 1e-12);
}

TEST(Pearson, Uncorrelated) { EXPECT_NEAR(pearsonOf({1, -1, 1, -1}, {1, 1, -1, -1}), 0.0, 1e-12); }

TEST(Pearson, IsSymmetric) {
    const std::vector<double> a{3, 1, 4, 1, 5, 9, 2, 6}, b{2, 7, 1, 8, 2, 8, 1, 8};
    EXPECT_DOUBLE_EQ(pearsonOf(a, b), pearsonOf(b, a));
}

TEST(Pearson, BothConstantAndEqualIsOne) {
    EXPECT_EQ(pearsonOf({2.5, 2.5, 2.5}, {2.5, 2.5, 2.5}), 1.0);
    // Two scans that see nothing at all (every histogram bin empty = 0).
    EXPECT_EQ(pearsonOf({0, 0, 0, 0}, {0, 0, 0, 0}), 1.0);
}

TEST(Pearson, EqualityToleranceIsRelativeToMagnitude) {
    // 1e-7 apart at 1000 m is within 1e-9 * 1000.
    EXPECT_EQ(pearsonOf({1000, 1000, 1000}, {1000 + 1e-7, 1000 + 1e-7, 1000 + 1e-7}), 1.0);
    // 1e-3 apart is not.
    EXPECT_EQ(pearsonOf({1000, 1000, 1000}, {1000.001, 1000.001, 1000.001}), 0.0);
    // An explicit, looser tolerance accepts it.
    const std::vector<double> a{1000, 1000, 1000}, b{1000.001, 1000.001, 1000.001};
    EXPECT_EQ(pearson(a.data(), b.data(), 3, 1e-5), 1.0);
}

TEST(Pearson, BothConstantButDifferentIsZero) {
    EXPECT_EQ(pearsonOf({2, 2, 2}, {3, 3, 3}), 0.0);
    EXPECT_EQ(pearsonOf({0, 0, 0}, {3, 3, 3}), 0.0);
}

TEST(Pearson, OneConstantIsZero) {
    EXPECT_EQ(pearsonOf({2, 2, 2, 2}, {1, 2, 3, 4}), 0.0);
    EXPECT_EQ(pearsonOf({1, 2, 3, 4}, {2, 2, 2, 2}), 0.0);
    // Even when the varying one has the constant one's mean.
    EXPECT_EQ(pearsonOf({1, 2, 3}, {2, 2, 2}), 0.0);
}

TEST(Pearson, VarianceBelowToleranceCountsAsConstant) {
    EXPECT_EQ(pearsonOf({1, 1 + 1e-13, 1}, {1, 2, 3}), 0.0);
}

TEST(Pearson, EmptyIsZero) { EXPECT_EQ(pearson(nullptr, nullptr, 0), 0.0); }

TEST(Pearson, MatchesTwoPassReferenceOnRandomInput) {
    std::mt19937 rng(20230101);
    std::uniform_real_distribution<double> range(0.0, 30.0);
    std::uniform_int_distribution<std::size_t> size(2, 40);
    std::uniform_real_distribution<double> mix(-1.0, 1.0);
    for (int trial = 0; trial < 2000; ++trial) {
        const std::size_t n = size(rng);
        std::vector<double> a(n), b(n);
        const double w = mix(rng);  // correlated, anti-correlated and unrelated pairs
        for (std::size_t i = 0; i < n; ++i) {
            a[i] = range(rng);
            b[i] = w * a[i] + (1.0 - std::abs(w)) * range(rng) + 15.0;
        }
        const double r = pearsonOf(a, b);
        ASSERT_NEAR(r, referencePearson(a, b), 1e-9) << "trial " << trial << " n " << n;
        ASSERT_GE(r, -1.0);
        ASSERT_LE(r, 1.0);
    }
}

TEST(Pearson, StaysInsideMinusOneOne) {
    // Rounding must never push |r| above 1, e.g. for a scaled copy.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> range(0.1, 30.0);
    for (int trial = 0; trial < 500; ++trial) {
        std::vector<double> a(20), b(20), c(20);
        for (std::size_t i = 0; i < a.size(); ++i) {
            a[i] = range(rng);
            b[i] = 0.3 * a[i] + 0.1;
            c[i] = -3.7 * a[i] + 100.0;
        }
        const double p = pearsonOf(a, b), q = pearsonOf(a, c);
        ASSERT_LE(p, 1.0);
        ASSERT_NEAR(p, 1.0, 1e-12);
        ASSERT_GE(q, -1.0);
        ASSERT_NEAR(q, -1.0, 1e-12);
    }
}

TEST(Similarity, ClampsNegativeCorrelationToZero) {
    EXPECT_EQ(similarityOf({1, 2, 3, 4}, {4, 3, 2, 1}), 0.0);
    EXPECT_EQ(similarityOf({1, 2, 3}, {3, 1, 2}), 0.0);  // pearson = -0.5
}

TEST(Similarity, KeepsPositiveCorrelation) {
    EXPECT_NEAR(similarityOf({1, 2, 3}, {1, 3, 2}), 0.5, 1e-12);
    EXPECT_NEAR(similarityOf({1, 2, 3, 4}, {2, 4, 6, 8}), 1.0, 1e-12);
    EXPECT_EQ(similarityOf({2, 2, 2}, {2, 2, 2}), 1.0);
    EXPECT_EQ(similarityOf({2, 2, 2}, {1, 2, 3}), 0.0);
}

}  // namespace
}  // namespace kfd
