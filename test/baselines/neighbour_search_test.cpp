#include "kfd/baselines/neighbour_search.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace kfd {
namespace {

using Indices = std::vector<std::uint32_t>;

struct Cloud {
    std::vector<float> x, y;
    std::size_t size() const { return x.size(); }
    void add(float px, float py) {
        x.push_back(px);
        y.push_back(py);
    }
};

/// All points within r (inclusive) of (qx, qy), with the same float arithmetic as the tree
/// (squared distance against r*r, all in float), in increasing index order.
Indices bruteForce(const Cloud& c, float qx, float qy, float r) {
    const float r2 = r * r;
    Indices out;
    for (std::size_t i = 0; i < c.size(); ++i) {
        const float dx = c.x[i] - qx, dy = c.y[i] - qy;
        if (dx * dx + dy * dy <= r2) out.push_back(static_cast<std::uint32_t>(i));
    }
    return out;
}

/// The tree's answer as a set: sorted, duplicates kept (so that a duplicate shows up as a
/// difference from the brute force, which has none).
Indices query(const NeighbourSearch2D& t, float qx, float qy, float r) {
    Indices out{12345u, 7u};  // must be cleared by the query
    t.radius(qx, qy, r, out);
    std::sort(out.begin(), out.end());
    return out;
}

/// Compares the tree with the brute force for a set of queries; returns the number of queries
/// whose answer was not empty (so callers can check the test is not vacuous).
std::size_t compareQueries(const NeighbourSearch2D& t, const Cloud& c,
                           const std::vector<std::vector<float>>& queries,
                           const std::string& what) {
    std::size_t nonEmpty = 0;
    for (const auto& q : queries) {
        const Indices expected = bruteForce(c, q[0], q[1], q[2]);
        const Indices got = query(t, q[0], q[1], q[2]);
        EXPECT_EQ(got, expected) << what << ": query (" << q[0] << ", " << q[1] << ") r " << q[2]
                                 << ", n " << c.size();
        if (got != expected) return nonEmpty;  // one report per point set is enough
        nonEmpty += !expected.empty();
    }
    return nonEmpty;
}

TEST(NeighbourSearch2D, EmptyTree) {
    NeighbourSearch2D t;
    const std::vector<float> none;
    t.build(none.data(), none.data(), 0);
    EXPECT_TRUE(query(t, 0.0f, 0.0f, 1e6f).empty());
    EXPECT_TRUE(query(t, 3.0f, -2.0f, 0.0f).empty());
}

TEST(NeighbourSearch2D, SinglePoint) {
    NeighbourSearch2D t;
    const std::vector<float> x{1.5f}, y{-2.0f};
    t.build(x.data(), y.data(), 1);
    EXPECT_EQ(query(t, 1.5f, -2.0f, 0.0f), Indices{0});  // radius 0: the point itself
    EXPECT_EQ(query(t, 1.5f, -1.0f, 1.0f), Indices{0});  // exactly at the radius
    EXPECT_TRUE(query(t, 1.5f, -1.0f, 0.999f).empty());
    EXPECT_TRUE(query(t, -10.0f, 10.0f, 5.0f).empty());
}

TEST(NeighbourSearch2D, TwoPoints) {
    NeighbourSearch2D t;
    const std::vector<float> x{0.0f, 4.0f}, y{0.0f, 0.0f};
    t.build(x.data(), y.data(), 2);
    EXPECT_EQ(query(t, 2.0f, 0.0f, 2.0f), (Indices{0, 1}));  // both exactly at r
    EXPECT_EQ(query(t, 1.0f, 0.0f, 2.0f), Indices{0});
    EXPECT_EQ(query(t, 3.0f, 0.0f, 1.0f), Indices{1});
    EXPECT_TRUE(query(t, 2.0f, 0.0f, 1.99f).empty());
    EXPECT_TRUE(query(t, 2.0f, 3.0f, 2.0f).empty());
    // Two identical points are both returned.
    const std::vector<float> same{7.0f, 7.0f};
    t.build(same.data(), same.data(), 2);
    EXPECT_EQ(query(t, 7.0f, 7.0f, 0.0f), (Indices{0, 1}));
    EXPECT_TRUE(query(t, 7.0f, 7.5f, 0.25f).empty());
}

TEST(NeighbourSearch2D, BoundaryIsInclusive) {
    // Pythagorean points at distance exactly 5 (squared distances exactly 25 in float) around
    // (1, 1), mixed with points just outside and inside, on both sides of every split.
    Cloud c;
    const float d[][2] = {{3, 4},  {-3, 4},  {3, -4}, {-3, -4}, {4, 3}, {-4, 3},
                          {4, -3}, {-4, -3}, {5, 0},  {-5, 0},  {0, 5}, {0, -5}};
    for (const auto& p : d) c.add(1.0f + p[0], 1.0f + p[1]);
    for (const auto& p : d) c.add(1.0f + p[0] * 1.001f, 1.0f + p[1] * 1.001f);  // outside
    for (const auto& p : d) c.add(1.0f + p[0] * 0.999f, 1.0f + p[1] * 0.999f);  // inside
    NeighbourSearch2D t;
    t.build(c.x.data(), c.y.data(), c.size());
    Indices expected;
    for (std::uint32_t i = 0; i < 12; ++i) expected.push_back(i);
    for (std::uint32_t i = 24; i < 36; ++i) expected.push_back(i);
    ASSERT_EQ(bruteForce(c, 1.0f, 1.0f, 5.0f), expected);  // the construction is as intended
    EXPECT_EQ(query(t, 1.0f, 1.0f, 5.0f), expected);
}

/// Random point sets of several kinds; n from 0 upwards, including 1 and 2.
Cloud randomCloud(std::mt19937& rng, int kind, std::size_t n) {
    std::uniform_real_distribution<float> u(-10.0f, 10.0f);
    std::uniform_int_distribution<int> grid(-6, 6);
    std::uniform_int_distribution<int> coin(0, 3);
    Cloud c;
    for (std::size_t i = 0; i < n; ++i) {
        switch (kind) {
            case 0:  // uniform
                c.add(u(rng), u(rng));
                break;
            case 1:  // integer grid: many duplicates and many points exactly at integer radii
                c.add(static_cast<float>(grid(rng)), static_cast<float>(grid(rng)));
                break;
            case 2:  // collinear on a vertical line (every x-split is a tie)
                c.add(2.5f, static_cast<float>(grid(rng)) * 0.5f);
                break;
            case 3:  // collinear on a horizontal line, continuous
                c.add(u(rng), -1.0f);
                break;
            case 4:  // collinear on the diagonal, integer steps
            {
                const float t = static_cast<float>(grid(rng));
                c.add(t, t);
                break;
            }
            case 5:  // a few distinct points repeated many times
                c.add(static_cast<float>(coin(rng)), static_cast<float>(coin(rng) % 2));
                break;
            default:  // clumps: uniform plus exact copies of earlier points
                if (i > 0 && coin(rng) == 0) {
                    const std::size_t j = std::uniform_int_distribution<std::size_t>(0, i - 1)(rng);
                    c.add(c.x[j], c.y[j]);
                } else {
                    c.add(u(rng), u(rng));
                }
                break;
        }
    }
    return c;
}

/// A random cloud (see randomCloud), built into the tree.
Cloud buildRandomCloud(NeighbourSearch2D& t, std::mt19937& rng, int kind, std::size_t n) {
    Cloud c = randomCloud(rng, kind, n);
    t.build(c.x.data(), c.y.data(), c.size());
    return c;
}

/// Names a random point set in failure messages.
std::string setName(unsigned seed, int kind, std::size_t n) {
    return "seed " + std::to_string(seed) + " kind " + std::to_string(kind) + " n " +
           std::to_string(n);
}

/// The first n points of a cloud.
Cloud prefixOf(const Cloud& c, std::size_t n) {
    Cloud p;
    for (std::size_t i = 0; i < n; ++i) p.add(c.x[i], c.y[i]);
    return p;
}

std::vector<std::vector<float>> randomQueries(std::mt19937& rng, const Cloud& c) {
    std::uniform_real_distribution<float> u(-12.0f, 12.0f);
    std::uniform_real_distribution<float> radius(0.0f, 8.0f);
    std::uniform_int_distribution<int> intRadius(0, 8);
    std::vector<std::vector<float>> q;
    for (int k = 0; k < 20; ++k) {
        q.push_back({u(rng), u(rng), radius(rng)});
        // Integer centre and radius: on the integer kinds, hits exactly at the radius.
        q.push_back({std::round(u(rng)), std::round(u(rng)), static_cast<float>(intRadius(rng))});
    }
    for (std::size_t k = 0; k < std::min<std::size_t>(c.size(), 20); ++k) {
        // Centred on a data point, radius 0 (its duplicates), integer and random radii.
        const std::size_t j = std::uniform_int_distribution<std::size_t>(0, c.size() - 1)(rng);
        q.push_back({c.x[j], c.y[j], 0.0f});
        q.push_back({c.x[j], c.y[j], static_cast<float>(intRadius(rng))});
        q.push_back({c.x[j], c.y[j], radius(rng)});
    }
    q.push_back({0.0f, 0.0f, 100.0f});  // everything
    return q;
}

TEST(NeighbourSearch2D, MatchesBruteForceOnRandomSets) {
    const std::size_t sizes[] = {0, 1, 2, 3, 4, 5, 7, 8, 9, 16, 17, 31, 64, 100, 257, 1000};
    NeighbourSearch2D t;  // one tree, rebuilt for every set (sizes go up and down)
    std::size_t sets = 0, nonEmpty = 0;
    for (unsigned seed = 1; seed <= 30; ++seed) {
        std::mt19937 rng(seed);
        for (int kind = 0; kind <= 6; ++kind) {
            for (const std::size_t n : sizes) {
                const Cloud c = buildRandomCloud(t, rng, kind, n);
                const std::string what = setName(seed, kind, n);
                nonEmpty += compareQueries(t, c, randomQueries(rng, c), what);
                ++sets;
                if (HasFailure()) return;
            }
        }
    }
    EXPECT_EQ(sets, 30u * 7u * 16u);
    EXPECT_GT(nonEmpty, sets * 10);  // most queries do find points
}

TEST(NeighbourSearch2D, BoundaryHitsOnIntegerGrid) {
    // A full 13 x 13 integer grid, every point twice: queries at integer radii put many points
    // exactly on the circle (e.g. (3,4) at radius 5), all of which must be returned.
    Cloud c;
    for (int rep = 0; rep < 2; ++rep)
        for (int i = -6; i <= 6; ++i)
            for (int j = -6; j <= 6; ++j) c.add(static_cast<float>(i), static_cast<float>(j));
    NeighbourSearch2D t;
    t.build(c.x.data(), c.y.data(), c.size());
    std::size_t onCircle = 0;
    for (int qx = -3; qx <= 3; ++qx)
        for (int qy = -3; qy <= 3; ++qy)
            for (int r = 0; r <= 9; ++r) {
                const float fx = static_cast<float>(qx), fy = static_cast<float>(qy),
                            fr = static_cast<float>(r);
                const Indices expected = bruteForce(c, fx, fy, fr);
                ASSERT_EQ(query(t, fx, fy, fr), expected)
                    << "query (" << qx << ", " << qy << ") r " << r;
                for (const auto i : expected) {
                    const float dx = c.x[i] - fx, dy = c.y[i] - fy;
                    onCircle += (dx * dx + dy * dy == fr * fr);
                }
            }
    EXPECT_GT(onCircle, 1000u);  // the boundary case is exercised
}

TEST(NeighbourSearch2D, AllPointsIdentical) {
    const std::vector<float> x(500, 3.25f), y(500, -1.5f);
    NeighbourSearch2D t;
    t.build(x.data(), y.data(), x.size());
    const Indices all = query(t, 3.25f, -1.5f, 0.0f);
    ASSERT_EQ(all.size(), 500u);
    for (std::uint32_t i = 0; i < 500; ++i) EXPECT_EQ(all[i], i);
    EXPECT_EQ(query(t, 4.25f, -1.5f, 1.0f).size(), 500u);
    EXPECT_TRUE(query(t, 4.25f, -1.5f, 0.99f).empty());
}

TEST(NeighbourSearch2D, RebuildWithFewerPointsReusesObject) {
    std::mt19937 rng(7);
    NeighbourSearch2D t;
    const Cloud big = randomCloud(rng, 0, 800);
    t.build(big.x.data(), big.y.data(), big.size());
    EXPECT_EQ(query(t, 0.0f, 0.0f, 100.0f).size(), 800u);

    // Fewer points of the same arrays: no index >= n may come back.
    t.build(big.x.data(), big.y.data(), 10);
    const Cloud prefix = prefixOf(big, 10);
    ASSERT_EQ(query(t, 0.0f, 0.0f, 100.0f), (Indices{0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
    compareQueries(t, prefix, randomQueries(rng, prefix), "prefix of the old arrays");

    // Fewer points, in other (shorter) arrays.
    const Cloud small = randomCloud(rng, 0, 5);
    t.build(small.x.data(), small.y.data(), small.size());
    EXPECT_EQ(query(t, 0.0f, 0.0f, 100.0f), (Indices{0, 1, 2, 3, 4}));
    compareQueries(t, small, randomQueries(rng, small), "after shrinking");

    // Down to nothing and up again.
    t.build(small.x.data(), small.y.data(), 0);
    EXPECT_TRUE(query(t, 0.0f, 0.0f, 100.0f).empty());
    const Cloud again = randomCloud(rng, 1, 300);
    t.build(again.x.data(), again.y.data(), again.size());
    compareQueries(t, again, randomQueries(rng, again), "after growing again");

    // Same arrays, changed values: a rebuild sees the new coordinates.
    Cloud moved = again;
    for (auto& v : moved.x) v += 100.0f;
    t.build(moved.x.data(), moved.y.data(), moved.size());
    EXPECT_TRUE(query(t, 0.0f, 0.0f, 20.0f).empty());
    compareQueries(t, moved, randomQueries(rng, moved), "after moving");
}

TEST(NeighbourSearch2D, OutputIsClearedFirst) {
    const std::vector<float> x{0.0f, 1.0f}, y{0.0f, 0.0f};
    NeighbourSearch2D t;
    t.build(x.data(), y.data(), 2);
    std::vector<std::uint32_t> out{9, 9, 9};
    t.radius(50.0f, 50.0f, 1.0f, out);
    EXPECT_TRUE(out.empty());
    out.assign(4, 9);
    t.radius(0.0f, 0.0f, 0.5f, out);
    EXPECT_EQ(out, Indices{0});
}

// --- k nearest neighbours ---------------------------------------------------------------------

struct Knn {
    Indices idx;
    std::vector<float> dist2;
};

/// The min(k, n) points nearest to (qx, qy) by exhaustive search: squared distances in float as
/// the tree computes them, ordered by (distance, index).
Knn bruteKnn(const Cloud& c, float qx, float qy, std::size_t k) {
    std::vector<std::pair<float, std::uint32_t>> all;
    for (std::size_t i = 0; i < c.size(); ++i) {
        const float dx = c.x[i] - qx, dy = c.y[i] - qy;
        all.emplace_back(dx * dx + dy * dy, static_cast<std::uint32_t>(i));
    }
    std::sort(all.begin(), all.end());
    Knn out;
    for (std::size_t i = 0; i < std::min(k, all.size()); ++i) {
        out.dist2.push_back(all[i].first);
        out.idx.push_back(all[i].second);
    }
    return out;
}

Knn treeKnn(const NeighbourSearch2D& t, float qx, float qy, std::size_t k) {
    Knn out;
    out.idx = {12345u, 7u};  // must be cleared by the query
    out.dist2 = {-1.0f};
    t.knn(qx, qy, k, out.idx, out.dist2);
    return out;
}

/// Compares knn with the brute force for the given queries and every k in `ks` (one exhaustive
/// sort per query, sliced for each k). Counts the queries where the k-th and (k+1)-th nearest
/// are equally far (the index tie-break decides), so callers can check that ties are exercised.
void compareKnn(const NeighbourSearch2D& t, const Cloud& c,
                const std::vector<std::vector<float>>& queries, const std::vector<std::size_t>& ks,
                const std::string& what, std::size_t& boundaryTies) {
    for (const auto& q : queries) {
        const Knn all = bruteKnn(c, q[0], q[1], c.size());
        for (const std::size_t k : ks) {
            const std::size_t kept = std::min(k, c.size());
            const Indices wantIdx(all.idx.begin(), all.idx.begin() + kept);
            const std::vector<float> wantD2(all.dist2.begin(), all.dist2.begin() + kept);
            const Knn got = treeKnn(t, q[0], q[1], k);
            ASSERT_EQ(got.idx, wantIdx)
                << what << ": query (" << q[0] << ", " << q[1] << ") k " << k << ", n " << c.size();
            ASSERT_EQ(got.dist2, wantD2)
                << what << ": query (" << q[0] << ", " << q[1] << ") k " << k << ", n " << c.size();
            boundaryTies += k > 0 && k < c.size() && all.dist2[k] == all.dist2[k - 1];
        }
    }
}

TEST(NeighbourSearch2DKnn, EmptyTreeAndKZero) {
    NeighbourSearch2D t;
    const std::vector<float> none;
    t.build(none.data(), none.data(), 0);
    Knn r = treeKnn(t, 0.0f, 0.0f, 5);
    EXPECT_TRUE(r.idx.empty());
    EXPECT_TRUE(r.dist2.empty());
    const std::vector<float> x{1.0f, 2.0f}, y{0.0f, 0.0f};
    t.build(x.data(), y.data(), 2);
    r = treeKnn(t, 0.0f, 0.0f, 0);
    EXPECT_TRUE(r.idx.empty());
    EXPECT_TRUE(r.dist2.empty());
}

TEST(NeighbourSearch2DKnn, HandMadeOrderTiesAndShortSets) {
    // Points on the x axis at 0, 1, 2, 3 and a copy of 1 (index 4); a query at 1.
    const std::vector<float> x{0.0f, 1.0f, 2.0f, 3.0f, 1.0f}, y(5, 0.0f);
    NeighbourSearch2D t;
    t.build(x.data(), y.data(), x.size());
    Knn r = treeKnn(t, 1.0f, 0.0f, 1);
    EXPECT_EQ(r.idx, Indices{1});  // itself, not excluded; the copy loses the index tie
    EXPECT_EQ(r.dist2, std::vector<float>{0.0f});
    r = treeKnn(t, 1.0f, 0.0f, 3);
    EXPECT_EQ(r.idx, (Indices{1, 4, 0}));  // 0 and 2 tie at distance 1: the lower index wins
    EXPECT_EQ(r.dist2, (std::vector<float>{0.0f, 0.0f, 1.0f}));
    r = treeKnn(t, 1.0f, 0.0f, 4);
    EXPECT_EQ(r.idx, (Indices{1, 4, 0, 2}));
    r = treeKnn(t, 1.0f, 0.0f, 50);  // k > n: every point, nearest first
    EXPECT_EQ(r.idx, (Indices{1, 4, 0, 2, 3}));
    EXPECT_EQ(r.dist2, (std::vector<float>{0.0f, 0.0f, 1.0f, 1.0f, 4.0f}));
    r = treeKnn(t, 2.6f, 0.0f, 2);  // off the data points
    EXPECT_EQ(r.idx, (Indices{3, 2}));
}

TEST(NeighbourSearch2DKnn, AllPointsIdenticalReturnsTheLowestIndices) {
    const std::vector<float> x(300, 3.25f), y(300, -1.5f);
    NeighbourSearch2D t;
    t.build(x.data(), y.data(), x.size());
    for (const std::size_t k : {1u, 9u, 299u, 300u, 400u}) {
        const Knn r = treeKnn(t, 3.25f, -1.5f, k);
        ASSERT_EQ(r.idx.size(), std::min<std::size_t>(k, 300));
        for (std::size_t i = 0; i < r.idx.size(); ++i) {
            EXPECT_EQ(r.idx[i], i);
            EXPECT_EQ(r.dist2[i], 0.0f);
        }
    }
}

TEST(NeighbourSearch2DKnn, MatchesBruteForceOnRandomSets) {
    const std::size_t sizes[] = {1, 2, 3, 4, 5, 7, 8, 9, 16, 17, 31, 64, 100, 257, 400};
    NeighbourSearch2D t;  // one tree, rebuilt for every set
    std::size_t sets = 0, ties = 0;
    for (unsigned seed = 1; seed <= 8; ++seed) {
        std::mt19937 rng(1000 + seed);
        for (int kind = 0; kind <= 6; ++kind) {
            for (const std::size_t n : sizes) {
                const Cloud c = buildRandomCloud(t, rng, kind, n);
                const std::string what = setName(seed, kind, n);
                std::vector<std::size_t> ks{0, 1, 2, 3, 5, 8, 9, 17};
                if (n <= 64) ks.insert(ks.end(), {n - 1, n, n + 3});  // k near and above n
                compareKnn(t, c, randomQueries(rng, c), ks, what, ties);
                ++sets;
                if (HasFailure()) return;
            }
        }
    }
    EXPECT_EQ(sets, 8u * 7u * 15u);
    EXPECT_GT(ties, 1000u);  // the integer kinds put many points at equal distances
}

TEST(NeighbourSearch2DKnn, ReusedOutputAndRebuiltTree) {
    std::mt19937 rng(5);
    NeighbourSearch2D t;
    Indices idx;
    std::vector<float> d2;
    const Cloud big = randomCloud(rng, 0, 500);
    t.build(big.x.data(), big.y.data(), big.size());
    t.knn(0.0f, 0.0f, 40, idx, d2);
    EXPECT_EQ(idx.size(), 40u);
    // Fewer points of the same arrays: no index >= n may come back, and the long previous
    // answer must not leak into the new one.
    t.build(big.x.data(), big.y.data(), 6);
    t.knn(0.0f, 0.0f, 40, idx, d2);
    const Cloud prefix = prefixOf(big, 6);
    const Knn want = bruteKnn(prefix, 0.0f, 0.0f, 40);
    EXPECT_EQ(idx, want.idx);
    EXPECT_EQ(d2, want.dist2);
    // The radius query still answers as before on the same tree.
    EXPECT_EQ(query(t, 0.0f, 0.0f, 100.0f), (Indices{0, 1, 2, 3, 4, 5}));
}

}  // namespace
}  // namespace kfd
