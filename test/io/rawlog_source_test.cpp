// The input layer: RawlogSource on tiny hand-made rawlogs (both layouts, plain and gzip), clean
// end of file against truncated files, the stamp rule and the odometry tracker.
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/io/CFileOutputStream.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationComment.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/poses/CPoint2D.h>
#include <mrpt/serialization/CArchive.h>
#include <sys/resource.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "kfd/io/open_source.h"
#include "kfd/io/rawlog_source.h"
#include "kfd/mrpt/allocation_limit.h"
#include "kfd/mrpt/scan_adapter.h"
#include "test_files.h"

namespace fs = std::filesystem;
using kfd::SourceEntry;
using Kind = kfd::SourceEntry::Kind;
using mrpt::poses::CPose2D;

namespace {

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_source_") {}
};

mrpt::obs::CObservation2DRangeScan::Ptr scan(double stamp, const std::string& label = "LASER") {
    auto s = std::make_shared<mrpt::obs::CObservation2DRangeScan>();
    s->sensorLabel = label;
    s->aperture = static_cast<float>(M_PI);
    s->resizeScan(5);
    for (std::size_t i = 0; i < 5; ++i) s->setScanRange(i, 1.0f + 0.1f * static_cast<float>(i));
    for (std::size_t i = 0; i < 5; ++i) s->setScanRangeValidity(i, true);
    // NaN: no timestamp (MRPT stamps a new observation with the current time).
    s->timestamp = std::isnan(stamp) ? mrpt::Clock::time_point() : mrpt::Clock::fromDouble(stamp);
    return s;
}

mrpt::obs::CActionCollection::Ptr action(const CPose2D& increment) {
    mrpt::obs::CActionRobotMovement2D m;
    m.computeFromOdometry(increment, mrpt::obs::CActionRobotMovement2D::TMotionModelOptions());
    auto a = std::make_shared<mrpt::obs::CActionCollection>();
    a->insert(m);
    return a;
}

mrpt::obs::CSensoryFrame::Ptr frame(std::initializer_list<mrpt::obs::CObservation::Ptr> obs) {
    auto sf = std::make_shared<mrpt::obs::CSensoryFrame>();
    for (const auto& o : obs) sf->insert(o);
    return sf;
}

mrpt::obs::CObservationOdometry::Ptr odometry(const CPose2D& pose) {
    auto o = std::make_shared<mrpt::obs::CObservationOdometry>();
    o->odometry = pose;
    return o;
}

using Objects = std::vector<mrpt::serialization::CSerializable::Ptr>;

// Writes the objects as a rawlog, gzip or plain.
void write(const std::string& path, const Objects& objects, bool gzip) {
    auto put = [&](auto& stream) {
        auto arch = mrpt::serialization::archiveFrom(stream);
        for (const auto& o : objects) arch << *o;
    };
    if (gzip) {
        mrpt::io::CFileGZOutputStream f(path);
        put(f);
    } else {
        mrpt::io::CFileOutputStream f(path);
        put(f);
    }
}

std::vector<SourceEntry> readAll(const std::string& path) {
    kfd::RawlogSource source(path);
    std::vector<SourceEntry> v;
    SourceEntry e;
    while (source.next(e)) v.push_back(e);
    return v;
}

std::string bytes(const std::string& path) { return kfd::test::fileBytes(path); }

void cut(const std::string& from, const std::string& to, std::size_t size) {
    std::ofstream(to, std::ios::binary) << bytes(from).substr(0, size);
}

// Sizes of the plain serialization of the first k objects (object boundaries in a plain file).
std::vector<std::size_t> boundaries(const TempDir& dir, const Objects& objects) {
    std::vector<std::size_t> b;
    for (std::size_t k = 1; k <= objects.size(); ++k) {
        write(dir / "prefix.rawlog", Objects(objects.begin(), objects.begin() + k), false);
        b.push_back(fs::file_size(dir / "prefix.rawlog"));
    }
    return b;
}

void expectPose(const std::optional<kfd::Pose2D>& p, const CPose2D& q) {
    ASSERT_TRUE(p.has_value());
    EXPECT_DOUBLE_EQ(p->x, q.x());
    EXPECT_DOUBLE_EQ(p->y, q.y());
    EXPECT_DOUBLE_EQ(p->phi, q.phi());
}

Objects observationsLog() {
    return {scan(100.0), odometry(CPose2D(1.0, 2.0, 0.5)), scan(100.2),
            std::make_shared<mrpt::poses::CPoint2D>(3.0, 4.0), scan(std::nan(""))};
}

Objects actionsLog() {
    return {action(CPose2D(1.0, 0.0, 0.5)),
            frame({scan(10.0)}),
            action(CPose2D(0.5, 0.5, -0.25)),
            frame({scan(10.2), scan(10.2, "LASER2")}),
            action(CPose2D(0.0, 1.0, 0.0)),  // lone: followed by a frame-less object
            std::make_shared<mrpt::poses::CPoint2D>(1.0, 1.0),
            frame({scan(10.4)})};  // a frame without an action
}

}  // namespace

TEST(RawlogSource, ObservationsLayoutPlainAndGzip) {
    TempDir dir;
    for (bool gzip : {false, true}) {
        SCOPED_TRACE(gzip ? "gzip" : "plain");
        write(dir / "obs.rawlog", observationsLog(), gzip);
        EXPECT_EQ(bytes(dir / "obs.rawlog").substr(0, 2) == "\x1f\x8b", gzip);
        const auto v = readAll(dir / "obs.rawlog");
        ASSERT_EQ(v.size(), 5u);
        const std::vector<Kind> kinds{Kind::Observation, Kind::Observation, Kind::Observation,
                                      Kind::Other, Kind::Observation};
        for (std::size_t i = 0; i < v.size(); ++i) {
            EXPECT_EQ(v[i].kind, kinds[i]) << i;
            EXPECT_EQ(v[i].index, i);
            EXPECT_EQ(v[i].objects_read, i + 1);
            EXPECT_FALSE(v[i].action || v[i].frame);
        }
        EXPECT_TRUE(v[3].other);
        EXPECT_FALSE(v[3].observation);
        // The odometry observation's absolute pose, from it on.
        EXPECT_FALSE(v[0].odometry.has_value());
        for (std::size_t i = 1; i < v.size(); ++i) expectPose(v[i].odometry, CPose2D(1, 2, 0.5));
        std::vector<double> stamps;
        for (const auto& e : v)
            e.forEachScan([&](const auto& s) { stamps.push_back(kfd::stampOf(*s)); });
        ASSERT_EQ(stamps.size(), 3u);
        EXPECT_NEAR(stamps[0], 100.0, 1e-6);
        EXPECT_NEAR(stamps[1], 100.2, 1e-6);
        EXPECT_TRUE(std::isnan(stamps[2]));  // no timestamp: unknown
    }
}

TEST(RawlogSource, ActionsLayoutPairsActionsWithTheirFrames) {
    TempDir dir;
    for (bool gzip : {false, true}) {
        SCOPED_TRACE(gzip ? "gzip" : "plain");
        write(dir / "act.rawlog", actionsLog(), gzip);
        const auto v = readAll(dir / "act.rawlog");
        ASSERT_EQ(v.size(), 5u);
        EXPECT_EQ(v[0].kind, Kind::Frame);
        EXPECT_TRUE(v[0].action && v[0].frame);
        EXPECT_EQ(v[1].kind, Kind::Frame);
        EXPECT_EQ(v[1].frame->size(), 2u);
        EXPECT_EQ(v[2].kind, Kind::Action);
        EXPECT_FALSE(v[2].frame);
        EXPECT_EQ(v[3].kind, Kind::Other);
        EXPECT_EQ(v[4].kind, Kind::Frame);
        EXPECT_FALSE(v[4].action);
        const std::vector<std::size_t> read{2, 4, 5, 6, 7};
        for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i].objects_read, read[i]) << i;
        // Integrated increments, composed as poses (not added).
        const CPose2D p1 = CPose2D() + CPose2D(1.0, 0.0, 0.5);
        const CPose2D p2 = p1 + CPose2D(0.5, 0.5, -0.25);
        const CPose2D p3 = p2 + CPose2D(0.0, 1.0, 0.0);
        expectPose(v[0].odometry, p1);
        expectPose(v[1].odometry, p2);
        expectPose(v[2].odometry, p3);
        expectPose(v[4].odometry, p3);
        EXPECT_NE(v[1].odometry->x, 1.5);  // the first heading rotated the second increment
        // Every object comes back once, in file order; four scans, stamped.
        std::size_t objects = 0, scans = 0;
        for (const auto& e : v) {
            e.forEachObject([&](const auto&) { ++objects; });
            e.forEachScan([&](const auto& s) {
                ++scans;
                EXPECT_FALSE(std::isnan(kfd::stampOf(*s)));
            });
        }
        EXPECT_EQ(objects, 7u);
        EXPECT_EQ(scans, 4u);
    }
}

TEST(RawlogSource, StampRuleIsSharedWithTheCoreScan) {
    kfd::Scan core;
    const auto stamped = scan(1234.5);
    kfd::toCore(*stamped, core);
    EXPECT_EQ(core.timestamp, kfd::stampOf(*stamped));
    EXPECT_NEAR(kfd::stampOf(*stamped), 1234.5, 1e-6);
    const auto unstamped = scan(std::nan(""));
    kfd::toCore(*unstamped, core);
    EXPECT_TRUE(std::isnan(core.timestamp));
    EXPECT_TRUE(std::isnan(kfd::stampOf(*unstamped)));
    EXPECT_EQ(kfd::stampForOutput(kfd::stampOf(*unstamped)), 0.0);
    EXPECT_EQ(kfd::stampForOutput(12.25), 12.25);
}

TEST(RawlogSource, OdometryTrackerFollowsActionsAndOdometryObservations) {
    kfd::OdometryTracker t;
    EXPECT_FALSE(t.current().has_value());
    mrpt::obs::CObservationComment comment;
    t.onObservation(comment);  // not odometry: ignored
    EXPECT_FALSE(t.current().has_value());
    t.onAction(mrpt::obs::CActionCollection());  // no movement: ignored
    EXPECT_FALSE(t.current().has_value());
    t.onAction(*action(CPose2D(1.0, 0.0, M_PI / 2)));
    t.onAction(*action(CPose2D(1.0, 0.0, 0.0)));
    expectPose(t.current(), CPose2D(1.0, 1.0, M_PI / 2));
    t.onObservation(*odometry(CPose2D(-3.0, 4.0, 0.1)));  // absolute: replaces
    expectPose(t.current(), CPose2D(-3.0, 4.0, 0.1));
}

TEST(RawlogSource, CleanEndAtAnObjectBoundaryButTruncatedFilesThrow) {
    TempDir dir;
    const Objects objects = actionsLog();
    write(dir / "full.rawlog", objects, false);
    const auto b = boundaries(dir, objects);
    ASSERT_EQ(b.back(), fs::file_size(dir / "full.rawlog"));
    // Cut exactly after the third object: a valid, shorter rawlog.
    cut(dir / "full.rawlog", dir / "boundary.rawlog", b[2]);
    const auto v = readAll(dir / "boundary.rawlog");
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[1].kind, Kind::Action);  // its frame is gone
    // Cut inside every object (and inside the header of the next one): an error.
    for (std::size_t k = 0; k < b.size(); ++k) {
        const std::size_t start = k == 0 ? 0 : b[k - 1];
        for (std::size_t size : {start + 1, start + 3, (start + b[k]) / 2, b[k] - 1}) {
            SCOPED_TRACE("cut at " + std::to_string(size));
            cut(dir / "full.rawlog", dir / "cut.rawlog", size);
            try {
                readAll(dir / "cut.rawlog");
                ADD_FAILURE() << "no error";
            } catch (const kfd::RawlogError& e) {
                const kfd::Error& base = e;  // one exception root
                EXPECT_NE(std::string(base.what()).find("cannot read object #"), std::string::npos);
                EXPECT_EQ(base.field(), dir / "cut.rawlog");
            }
        }
    }
}

TEST(RawlogSource, TruncatedGzipThrowsEvenWhenItsDataEndsAtABoundary) {
    TempDir dir;
    write(dir / "full.rawlog", actionsLog(), true);
    const std::size_t size = fs::file_size(dir / "full.rawlog");
    EXPECT_EQ(readAll(dir / "full.rawlog").size(), 5u);
    // The gzip header alone (no data, so CArchive sees a clean end), the trailer missing, and
    // a cut in the middle of the compressed data.
    for (std::size_t cut_at : {std::size_t{10}, size - 8, size - 1, size / 2}) {
        SCOPED_TRACE("cut at " + std::to_string(cut_at) + " of " + std::to_string(size));
        cut(dir / "full.rawlog", dir / "cut.rawlog", cut_at);
        EXPECT_THROW(readAll(dir / "cut.rawlog"), kfd::SourceError);
    }
}

// The gzip trailer is verified at the end of the stream: a wrong CRC-32 or length, or bytes
// after the stream that are not another gzip member, are errors; a second member is read on.
TEST(RawlogSource, GzipTrailerAndTrailingBytesAreChecked) {
    TempDir dir;
    write(dir / "full.rawlog", actionsLog(), true);
    const std::string full = bytes(dir / "full.rawlog");
    auto expectError = [&](const std::string& data, const std::string& reason) {
        SCOPED_TRACE(reason);
        std::ofstream(dir / "bad.rawlog", std::ios::binary) << data;
        try {
            readAll(dir / "bad.rawlog");
            ADD_FAILURE() << "no error";
        } catch (const kfd::RawlogError& e) {
            EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
        }
    };
    std::string crc = full;
    crc[crc.size() - 8] = static_cast<char>(crc[crc.size() - 8] ^ 0x10);
    expectError(crc, "incorrect data check");
    std::string isize = full;
    isize[isize.size() - 2] = static_cast<char>(isize[isize.size() - 2] ^ 0x01);
    expectError(isize, "incorrect length check");
    expectError(full.substr(0, full.size() - 8), "the gzip stream ends early");
    expectError(full.substr(0, full.size() - 3), "the gzip stream ends early");
    expectError(full + "garbage", "garbage after the gzip stream");
    expectError(full + std::string(1, '\0'), "garbage after the gzip stream");
    // Two members (as `cat a.gz b.gz` makes): one stream of both logs.
    std::ofstream(dir / "two.rawlog", std::ios::binary) << full << full;
    EXPECT_EQ(readAll(dir / "two.rawlog").size(), 10u);
    EXPECT_EQ(readAll(dir / "full.rawlog").size(), 5u);
}

TEST(RawlogSource, TruncatedRealRawlogThrowsAndTheFullOneEndsCleanly) {
    const std::string real = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";
    if (!fs::exists(real)) GTEST_SKIP() << "missing " << real;
    TempDir dir;
    kfd::RawlogSource full(real);
    SourceEntry e;
    std::size_t scans = 0, entries = 0, objects = 0;
    while (full.next(e)) {
        ++entries;
        objects = e.objects_read;
        e.forEachScan([&](const auto&) { ++scans; });
    }
    EXPECT_EQ(objects, 1200u);  // a scan and an odometry observation per step
    EXPECT_EQ(entries, 1200u);
    EXPECT_EQ(scans, 600u);
    // Progress counts decoded bytes of the gzip file, and the total is its decoded size.
    EXPECT_GT(full.bytesTotal(), fs::file_size(real));
    EXPECT_EQ(full.bytesRead(), full.bytesTotal());
    // A cut gzip file fails when it is opened, before any object is read.
    cut(real, dir / "cut.rawlog", fs::file_size(real) / 2);
    try {
        kfd::RawlogSource cutSource(dir / "cut.rawlog");
        ADD_FAILURE() << "a truncated gzip rawlog opened without an error";
    } catch (const kfd::RawlogError& err) {
        EXPECT_NE(std::string(err.what()).find("truncated or corrupt"), std::string::npos);
    }
    // The same log decoded, then cut inside an object (half is a boundary: 600 equal pairs):
    // read up to the cut, then an error.
    {
        mrpt::io::CFileGZInputStream in(real);
        std::ofstream out(dir / "plain.rawlog", std::ios::binary);
        std::string buf(1 << 16, '\0');
        while (const std::size_t n = in.Read(buf.data(), buf.size())) out.write(buf.data(), n);
    }
    cut(dir / "plain.rawlog", dir / "cut-plain.rawlog",
        fs::file_size(dir / "plain.rawlog") / 2 + 100);
    kfd::RawlogSource cutSource(dir / "cut-plain.rawlog");
    std::size_t before_error = 0;
    try {
        while (cutSource.next(e)) ++before_error;
        ADD_FAILURE() << "a truncated rawlog ended without an error";
    } catch (const kfd::RawlogError& err) {
        EXPECT_NE(std::string(err.what()).find("truncated or corrupt"), std::string::npos);
    }
    EXPECT_GT(before_error, 100u);
    EXPECT_LT(before_error, 1200u);
}

// Regression (fuzz_rawlog): damaged compressed data decodes to garbage whose length fields
// MRPT's deserialisers trust; these 12 kB inputs made them allocate 1.3-2.7 GB before failing.
// The whole gzip stream is now checked first: each is refused when opened, and the process's
// peak memory stays far below what one such allocation took.
TEST(RawlogSource, DamagedGzipIsRefusedBeforeMrptDecodesAnyObject) {
    const fs::path corpus = fs::path(KFD_SOURCE_DIR) / "test/fuzz/corpus/rawlog";
    std::size_t n = 0;
    for (const auto& f : fs::directory_iterator(corpus)) {
        if (f.path().filename().string().rfind("finding-gzip-", 0) != 0) continue;
        SCOPED_TRACE(f.path().string());
        ++n;
        EXPECT_THROW(kfd::RawlogSource{f.path().string()}, kfd::RawlogError);
    }
    EXPECT_EQ(n, 4u);
    struct rusage u {};
    getrusage(RUSAGE_SELF, &u);
    EXPECT_LT(u.ru_maxrss, 1024L * 1024L);  // KiB: below 1 GiB
}

// A plain rawlog whose first scan's sensor label claims 4 GiB: MRPT would zero-fill a 4 GiB
// string before its read fails (4.2 GB resident, 6 s). With kfd::alloc_limit linked (as this
// test and every app are) the allocation is refused: a RawlogError naming the cause, the scans
// before it read, and peak memory far below the claim.
TEST(RawlogSource, ALengthFieldBeyondTheFileIsRefusedNotAllocated) {
    TempDir dir;
    write(dir / "log.rawlog", observationsLog(), false);
    std::string data = bytes(dir / "log.rawlog");
    const std::size_t first = data.find("LASER");
    ASSERT_NE(first, std::string::npos);
    const std::size_t at = data.find("LASER", first + 5);  // the second scan's label
    ASSERT_NE(at, std::string::npos);
    ASSERT_EQ(data.substr(at - 4, 4), std::string("\x05\0\0\0", 4));  // its length, 5
    data.replace(at - 4, 4, std::string("\xf0\xff\xff\xff", 4));
    std::ofstream(dir / "bad.rawlog", std::ios::binary) << data;
    kfd::RawlogSource src(dir / "bad.rawlog");
    SourceEntry e;
    std::size_t read = 0;
    try {
        while (src.next(e)) ++read;
        ADD_FAILURE() << "no error";
    } catch (const kfd::RawlogError& err) {
        EXPECT_NE(std::string(err.what()).find("a corrupt length field"), std::string::npos)
            << err.what();
    }
    EXPECT_EQ(read, 2u);  // the first scan and the odometry observation
    struct rusage u {};
    getrusage(RUSAGE_SELF, &u);
    EXPECT_LT(u.ru_maxrss, 1024L * 1024L);  // KiB: below 1 GiB
    // The bound is lifted after each object.
    EXPECT_EQ(kfd::allocationLimit(), SIZE_MAX);
}

// A plain rawlog whose second scan's beam count reads 0x40000000 or 0xFFFFFFFF: MRPT resizes
// the scan's three arrays (mrpt::aligned_std_vector, allocated by mrpt::aligned_malloc, not
// operator new) to it before reading: 9.5 GB for 0x40000000 and a segfault inside MRPT's
// allocator under a memory limit. kfd::alloc_limit's mrpt::aligned_malloc enforces the same
// bound as its operator new: a RawlogError at once, the objects before it read.
TEST(RawlogSource, ACorruptBeamCountIsRefusedNotAllocated) {
    TempDir dir;
    write(dir / "log.rawlog", observationsLog(), false);
    const std::string data = bytes(dir / "log.rawlog");
    const std::size_t first = data.find("LASER");
    ASSERT_NE(first, std::string::npos);
    const std::size_t at = kfd::test::scanBeamCountAt(data.find("LASER", first + 5), 5);
    ASSERT_EQ(data.substr(at, 4), std::string("\x05\0\0\0", 4));  // 5 beams
    for (const std::uint32_t count : {0x40000000u, 0xffffffffu, 0x01000000u}) {
        SCOPED_TRACE(count);
        std::ofstream(dir / "bad.rawlog", std::ios::binary | std::ios::trunc)
            << kfd::test::withU32(data, at, count);
        kfd::RawlogSource src(dir / "bad.rawlog");
        SourceEntry e;
        std::size_t read = 0;
        try {
            while (src.next(e)) ++read;
            ADD_FAILURE() << "no error";
        } catch (const kfd::RawlogError& err) {
            const std::string w = err.what();
            EXPECT_EQ(w.rfind("cannot read object #2 of " + (dir / "bad.rawlog"), 0), 0u) << w;
            // 0x01000000 beams (64 MiB of ranges) fit in the bound: MRPT then finds the bytes
            // missing.
            EXPECT_NE(w.find(count == 0x01000000u ? "Cannot read requested number of bytes"
                                                  : "(a corrupt length field)"),
                      std::string::npos)
                << w;
        }
        EXPECT_EQ(read, 2u);
    }
    struct rusage u {};
    getrusage(RUSAGE_SELF, &u);
    EXPECT_LT(u.ru_maxrss, 512L * 1024L);  // KiB
    EXPECT_EQ(kfd::allocationLimit(), SIZE_MAX);
}

TEST(RawlogSource, MissingEmptyOrForeignFilesAreRawlogErrors) {
    TempDir dir;
    EXPECT_THROW(kfd::RawlogSource(dir / "missing.rawlog"), kfd::RawlogError);
    std::ofstream(dir / "empty.rawlog").close();
    EXPECT_THROW(kfd::RawlogSource(dir / "empty.rawlog"), kfd::RawlogError);
    std::ofstream(dir / "text.rawlog") << "not a rawlog\n";
    kfd::RawlogSource text(dir / "text.rawlog");
    SourceEntry e;
    try {
        text.next(e);
        ADD_FAILURE() << "no error";
    } catch (const kfd::SourceError& err) {
        EXPECT_NE(std::string(err.what()).find("is it an MRPT rawlog?"), std::string::npos);
    }
    // openSource picks the rawlog reader.
    write(dir / "obs.rawlog", observationsLog(), true);
    auto src = kfd::openSource(dir / "obs.rawlog");
    std::size_t n = 0;
    while (src->next(e)) ++n;
    EXPECT_EQ(n, 5u);
    EXPECT_EQ(src->path(), dir / "obs.rawlog");
}
