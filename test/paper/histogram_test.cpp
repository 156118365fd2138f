#include "kfd/paper/histogram.h"

#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "test_scans.h"

namespace kfd {
namespace {

using test::makeScan;

Histogram makeHistogram(std::size_t bins) {
    Histogram::Params p;
    p.bins = bins;
    return Histogram(p);
}

TEST(Histogram, MeanRangePerEqualBin) {
    // 10 beams, 5 bins: bin b holds beams 2b and 2b+1.
    const Scan scan = makeScan({1, 2, 3, 4, 5, 6, 7, 8, 9, 10});
    std::vector<double> h;
    EXPECT_EQ(makeHistogram(5).compute(scan, h), 5u);
    EXPECT_EQ(h, (std::vector<double>{1.5, 3.5, 5.5, 7.5, 9.5}));
}

TEST(Histogram, BinsFollowBeamIndex) {
    // 10 beams, 3 bins: floor(i*3/10) puts beams 0-3, 4-6 and 7-9 together.
    const Scan scan = makeScan({1, 1, 1, 1, 2, 2, 2, 4, 4, 4});
    std::vector<double> h;
    makeHistogram(3).compute(scan, h);
    EXPECT_EQ(h, (std::vector<double>{1.0, 2.0, 4.0}));
}

TEST(Histogram, InvalidBeamsAreIgnoredInTheMean) {
    Scan scan = makeScan({1, 100, 3, 4});
    scan.valid[1] = 0;
    std::vector<double> h;
    EXPECT_EQ(makeHistogram(2).compute(scan, h), 2u);
    EXPECT_EQ(h, (std::vector<double>{1.0, 3.5}));
}

TEST(Histogram, EmptyBinIsZero) {
    Scan scan = makeScan({1, 2, 3, 4, 5, 6});
    scan.valid[2] = 0;
    scan.valid[3] = 0;
    std::vector<double> h;
    EXPECT_EQ(makeHistogram(3).compute(scan, h), 2u);
    EXPECT_EQ(h, (std::vector<double>{1.5, 0.0, 5.5}));
}

TEST(Histogram, MoreBinsThanBeams) {
    // 3 beams, 5 bins: beams land in bins 0, 1 and 3 (floor(i*5/3)); bins 2 and 4 are empty.
    const Scan scan = makeScan({2, 4, 6});
    std::vector<double> h;
    EXPECT_EQ(makeHistogram(5).compute(scan, h), 3u);
    EXPECT_EQ(h, (std::vector<double>{2.0, 4.0, 0.0, 6.0, 0.0}));
}

TEST(Histogram, OneBeamScan) {
    const Scan scan = makeScan({3.5f});
    std::vector<double> h;
    EXPECT_EQ(makeHistogram(4).compute(scan, h), 1u);
    EXPECT_EQ(h, (std::vector<double>{3.5, 0.0, 0.0, 0.0}));
}

TEST(Histogram, AllInvalidScan) {
    Scan scan = makeScan({1, 2, 3, 4, 5});
    scan.valid.assign(5, 0);
    std::vector<double> h{7.0, 7.0};
    EXPECT_EQ(makeHistogram(3).compute(scan, h), 0u);
    EXPECT_EQ(h, (std::vector<double>{0.0, 0.0, 0.0}));
}

TEST(Histogram, EmptyScan) {
    const Scan scan = makeScan({});
    std::vector<double> h;
    EXPECT_EQ(makeHistogram(3).compute(scan, h), 0u);
    EXPECT_EQ(h, (std::vector<double>{0.0, 0.0, 0.0}));
}

TEST(Histogram, OutputIsResizedAndOverwritten) {
    const Histogram hist = makeHistogram(2);
    std::vector<double> h(7, 42.0);
    hist.compute(makeScan({1, 1, 5, 5}), h);
    EXPECT_EQ(h, (std::vector<double>{1.0, 5.0}));
    // A second scan does not accumulate onto the first one.
    hist.compute(makeScan({2, 2, 2, 2}), h);
    EXPECT_EQ(h, (std::vector<double>{2.0, 2.0}));
}

TEST(Histogram, SingleBinIsTheMeanOfAllValidBeams) {
    Scan scan = makeScan({1, 2, 3, 10});
    scan.valid[3] = 0;
    std::vector<double> h;
    EXPECT_EQ(makeHistogram(1).compute(scan, h), 1u);
    EXPECT_EQ(h, (std::vector<double>{2.0}));
}

TEST(Histogram, ZeroBinsThrow) {
    EXPECT_THROW(makeHistogram(0), kfd::ParameterError);
    Histogram h;
    EXPECT_THROW(h.initialize(Histogram::Params{0}), kfd::ParameterError);
}

TEST(Histogram, DefaultIsTwentyBins) {
    const Histogram h;
    EXPECT_EQ(h.params().bins, 20u);
    std::vector<double> out;
    h.compute(makeScan({1, 2, 3}), out);
    EXPECT_EQ(out.size(), 20u);
}

}  // namespace
}  // namespace kfd
