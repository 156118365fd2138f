// Scan validation at the MRPT adapter (kfd::checkScan) and what RawlogFilter and StreamFilter
// do with a bad scan: a bad geometry skips it (counted per reason), bad ranges become invalid,
// non-finite odometry becomes unknown, and one bad scan never aborts a log.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "bad_logs.h"
#include "kfd/io/rawlog_filter.h"
#include "kfd/mrpt/scan_check.h"
#include "kfd/mrpt/stream_filter.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using kfd::ScanSkipReason;
using mrpt::obs::CObservation2DRangeScan;
constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr float kInff = std::numeric_limits<float>::infinity();

CObservation2DRangeScan room(double x = 0.0) {
    CObservation2DRangeScan s;
    kfd::test::roomScanInto(s, x, 1000.0);
    return s;
}

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_scancheck_") {}
};

}  // namespace

TEST(ScanCheck, AGoodScanPassesUnchanged) {
    auto s = room();
    const auto c = kfd::checkScan(s);
    EXPECT_TRUE(c.ok());
    EXPECT_EQ(c.bad_ranges, 0u);
    for (std::size_t i = 0; i < s.getScanSize(); ++i) EXPECT_TRUE(s.getScanRangeValidity(i));
}

TEST(ScanCheck, BadApertureRejectsTheScanAndChangesNothing) {
    for (const float a : {0.0f, -1.0f, kNaNf, kInff, 7.0f}) {
        auto s = room();
        s.aperture = a;
        s.setScanRange(3, kNaNf);  // would be marked invalid if the scan went on
        const auto c = kfd::checkScan(s);
        EXPECT_EQ(c.reject, ScanSkipReason::BadAperture) << a;
        EXPECT_TRUE(s.getScanRangeValidity(3)) << a;
    }
}

TEST(ScanCheck, AFullTurnInFloatIsAccepted) {
    auto s = room();
    s.aperture = static_cast<float>(2.0 * M_PI);  // float(2 pi) is a little above 2 pi
    EXPECT_TRUE(kfd::checkScan(s).ok());
}

TEST(ScanCheck, BeamCountOutsideTwoTo65536RejectsTheScan) {
    CObservation2DRangeScan s;
    s.aperture = static_cast<float>(M_PI);
    EXPECT_EQ(kfd::checkScan(s).reject, ScanSkipReason::NoBeams);
    s.resizeScanAndAssign(1, 1.0f, true);
    EXPECT_EQ(kfd::checkScan(s).reject, ScanSkipReason::NoBeams);
    s.resizeScanAndAssign(kfd::kMaxScanBeams + 1, 1.0f, true);
    EXPECT_EQ(kfd::checkScan(s).reject, ScanSkipReason::TooManyBeams);
    s.resizeScanAndAssign(kfd::kMaxScanBeams, 1.0f, true);
    EXPECT_TRUE(kfd::checkScan(s).ok());
    s.resizeScanAndAssign(2, 1.0f, true);
    EXPECT_TRUE(kfd::checkScan(s).ok());
}

TEST(ScanCheck, NonFiniteNegativeAndHugeRangesAreMarkedInvalidAndCounted) {
    auto s = room();
    s.setScanRange(0, kNaNf);
    s.setScanRange(1, kInff);
    s.setScanRange(2, -kInff);
    s.setScanRange(3, -0.5f);
    s.setScanRange(4, 1e30f);
    s.setScanRange(5, kNaNf);
    s.setScanRangeValidity(5, false);  // already invalid: not counted
    s.setScanRange(6, 0.0f);           // zero is a (short) measurement
    const auto c = kfd::checkScan(s);
    EXPECT_TRUE(c.ok());
    EXPECT_EQ(c.bad_ranges, 5u);
    for (std::size_t i = 0; i < 6; ++i) EXPECT_FALSE(s.getScanRangeValidity(i)) << i;
    EXPECT_TRUE(s.getScanRangeValidity(6));
    EXPECT_EQ(s.getScanRange(4), 1e30f);          // values are left as they were
    EXPECT_EQ(kfd::checkScan(s).bad_ranges, 0u);  // idempotent
}

TEST(ScanCheck, NonFiniteOdometryBecomesUnknownAndIsCounted) {
    auto s = room();
    std::optional<kfd::Pose2D> odo = kfd::Pose2D{1.0, std::nan(""), 0.0};
    const auto c = kfd::checkScan(s, &odo);
    EXPECT_TRUE(c.ok());
    EXPECT_TRUE(c.bad_odometry);
    EXPECT_FALSE(odo.has_value());
    std::optional<kfd::Pose2D> good = kfd::Pose2D{1.0, 2.0, 0.5};
    EXPECT_FALSE(kfd::checkScan(s, &good).bad_odometry);
    EXPECT_TRUE(good.has_value());
}

TEST(StreamFilter, BadGeometryIsSkippedBeforeAnyStageAndCounted) {
    kfd::StreamFilter f;
    auto s = room();
    s.aperture = 0.0f;
    const auto r = f.process(s);
    EXPECT_EQ(r.skipped, ScanSkipReason::BadAperture);
    EXPECT_FALSE(r.keep);
    EXPECT_EQ(r.report.stage_count, 0u);  // no stage ran
    EXPECT_EQ(f.sensorCount(), 0u);       // no pipeline was even built for it
    EXPECT_STREQ(r.record.reason, "skipped:bad_aperture");
    EXPECT_EQ(r.record.points_in, s.getScanSize());
    EXPECT_EQ(f.counters().scans_in, 1u);
    EXPECT_EQ(f.counters().scans_skipped, 1u);
    EXPECT_EQ(f.counters().scans_dropped, 0u);
    EXPECT_EQ(f.counters().skipped_by_reason[static_cast<std::size_t>(ScanSkipReason::BadAperture)],
              1u);
    // The next good scan is the sensor's first: a keyframe, numbered after the skipped one.
    auto good = room();
    const auto g = f.process(good);
    EXPECT_TRUE(g.keep);
    EXPECT_EQ(g.record.index, 1u);
    EXPECT_STREQ(g.record.reason, "first");
}

TEST(StreamFilter, CountersAddUpTheRecords) {
    kfd::StreamFilter f;
    std::size_t kept = 0, in = 0, removed = 0;
    for (int k = 0; k < 6; ++k) {
        auto s = room(0.01 * k);
        if (k == 2) s.setScanRange(5, kNaNf);
        const auto r = f.process(s, kfd::Pose2D{0.02 * k, 0.0, 0.0});
        EXPECT_EQ(r.record.index, static_cast<std::size_t>(k));
        EXPECT_EQ(r.record.kept, r.keep);
        ASSERT_TRUE(r.record.odometry.has_value());
        EXPECT_DOUBLE_EQ(r.record.odometry->x, 0.02 * k);
        kept += r.keep;
        in += r.record.points_in;
        if (r.keep) removed += r.record.points_in - r.record.points_out;
    }
    const kfd::ScanCounters& c = f.counters();
    EXPECT_EQ(c.scans_in, 6u);
    EXPECT_EQ(c.scans_kept, kept);
    EXPECT_EQ(c.scans_kept + c.scans_dropped, 6u);
    EXPECT_EQ(c.points_in, in);
    EXPECT_EQ(c.points_removed, removed);
    EXPECT_EQ(c.beams_bad_range, 1u);
}

TEST(StreamFilter, BadRangesAndOdometryAreRepairedAndReported) {
    kfd::StreamFilter f;
    auto s = room();
    s.setScanRange(10, -kInff);
    s.setScanRange(11, 1e30f);
    const auto r = f.process(s, kfd::Pose2D{std::nan(""), 0.0, 0.0});
    EXPECT_EQ(r.bad_ranges, 2u);
    EXPECT_TRUE(r.bad_odometry);
    EXPECT_TRUE(r.keep);  // first scan
    EXPECT_FALSE(s.getScanRangeValidity(10));
    EXPECT_FALSE(s.getScanRangeValidity(11));
}

TEST(StreamFilter, AStampGoingBackwardsIsAllowedAndFlagged) {
    kfd::StreamFilter f;
    auto a = room(), b = room(0.1), c = room(0.2);
    a.timestamp = mrpt::Clock::fromDouble(1000.0);
    b.timestamp = mrpt::Clock::fromDouble(999.0);
    c.timestamp = mrpt::Clock::fromDouble(1001.0);
    EXPECT_FALSE(f.process(a).stamp_backwards);
    EXPECT_TRUE(f.process(b).stamp_backwards);
    EXPECT_FALSE(f.process(c).stamp_backwards);
}

TEST(RawlogFilter, BadScansAreSkippedCountedAndDroppedWithoutAbortingTheLog) {
    TempDir dir;
    const std::string in = dir / "bad.rawlog";
    kfd::test::writeRoomLog(in, 12, [](int k, CObservation2DRangeScan& s) {
        if (k == 3) s.resizeScan(0);    // zero beams: aborted the log before
        if (k == 5) s.aperture = 0.0f;  // read past a buffer in the clustering
        if (k == 7) s.aperture = kNaNf;
        if (k == 8) s.setScanRange(20, -kInff);  // bad range: marked invalid, scan goes on
        if (k == 9) s.resizeScanAndAssign(kfd::kMaxScanBeams + 1, 2.0f, true);
    });
    const std::string before = kfd::test::fileBytes(in);
    kfd::RawlogFilterOptions o;
    o.input = in;
    o.output = dir / "out.rawlog";
    o.stats_csv = dir / "stats.csv";
    const auto s = kfd::RawlogFilter().run(o);
    EXPECT_EQ(kfd::test::fileBytes(in), before);
    EXPECT_EQ(s.scans_in, 12u);
    EXPECT_EQ(s.scans_skipped, 4u);
    EXPECT_EQ(s.skipped_by_reason[static_cast<std::size_t>(ScanSkipReason::NoBeams)], 1u);
    EXPECT_EQ(s.skipped_by_reason[static_cast<std::size_t>(ScanSkipReason::BadAperture)], 2u);
    EXPECT_EQ(s.skipped_by_reason[static_cast<std::size_t>(ScanSkipReason::TooManyBeams)], 1u);
    EXPECT_EQ(s.beams_bad_range, 1u);
    EXPECT_EQ(s.scans_kept + s.scans_dropped + s.scans_skipped, s.scans_in);

    // Skipped scans are not in the output; every scan that is has a usable geometry.
    kfd::RawlogSource out(o.output);
    kfd::SourceEntry e;
    std::size_t scans = 0;
    while (out.next(e))
        if (e.frame)
            for (const auto& ob : *e.frame)
                if (auto sc = std::dynamic_pointer_cast<CObservation2DRangeScan>(ob)) {
                    ++scans;
                    EXPECT_TRUE(kfd::checkScan(*sc).ok());
                }
    EXPECT_EQ(scans, s.scans_kept);

    // One stats row per input scan; skipped ones say why.
    std::ifstream csv(o.stats_csv);
    std::string line, text;
    std::size_t rows = 0;
    std::getline(csv, line);  // header
    while (std::getline(csv, line)) {
        ++rows;
        text += line + "\n";
    }
    EXPECT_EQ(rows, 12u);
    EXPECT_NE(text.find("3,1000.600000,LASER,0,skipped:no_beams,"), std::string::npos) << text;
    EXPECT_NE(text.find(",skipped:bad_aperture,"), std::string::npos) << text;
    EXPECT_NE(text.find(",skipped:too_many_beams,"), std::string::npos) << text;
}

TEST(RawlogFilter, NonFiniteOdometryIsUnknownForThatScanOnly) {
    TempDir dir;
    const std::string in = dir / "nan_odo.rawlog";
    kfd::test::writeRoomObservationLog(in, 8, {}, [](int k, mrpt::poses::CPose2D& pose) {
        if (k == 4) pose = mrpt::poses::CPose2D(std::nan(""), 0.0, 0.0);
    });
    kfd::RawlogFilterOptions o;
    o.input = in;
    o.output = dir / "out.rawlog";
    const auto s = kfd::RawlogFilter().run(o);
    EXPECT_EQ(s.odometry_bad, 1u);
    EXPECT_EQ(s.scans_skipped, 0u);
    EXPECT_EQ(s.scans_in, 8u);
}
