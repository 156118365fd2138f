// The CARMEN source on tiny hand-written logs (every line kind, PARAMs, gzip, bad lines), the
// format detection, and mit-csail.clf against the rawlog made from it.
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <sys/resource.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "kfd/io/carmen_source.h"
#include "kfd/io/open_source.h"
#include "kfd/io/rawlog_source.h"
#include "kfd/io/source_listing.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/stream_filter.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using kfd::SourceEntry;
using Scan2D = mrpt::obs::CObservation2DRangeScan;
using Odo = mrpt::obs::CObservationOdometry;

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_carmen_") {}
    std::string write(const std::string& name, const std::string& text, bool gzip = false) const {
        const std::string p = *this / name;
        if (gzip) {
            mrpt::io::CFileGZOutputStream f(p);
            f.Write(text.data(), text.size());
        } else {
            std::ofstream(p, std::ios::binary) << text;
        }
        return p;
    }
};

std::vector<SourceEntry> readAll(const std::string& path) {
    kfd::CarmenSource src(path);
    std::vector<SourceEntry> v;
    SourceEntry e;
    while (src.next(e)) v.push_back(e);
    return v;
}

template <class T>
const T* as(const SourceEntry& e) {
    return dynamic_cast<const T*>(e.observation.get());
}

const std::string kLog =
    "# a comment\n"
    "PARAM robot_front_laser_max 5.0 host 0\n"
    "PARAM laser_front_laser_resolution 1.0 host 0\n"
    "ODOM 1.0 2.0 0.1 0.0 0.0 0.0 100.25 host 0.0\n"
    "FLASER 4 1.0 0 5.0 2.5 1.1 2.0 0.1 1.0 2.0 0.1 100.5 host 0.25\n"
    "TRUEPOS 1 2 3 4 5 6 100.6 host 0.3\n"
    "\n"
    "RAWLASER1 0 -1.5 3.0 0.01 8.0 0.01 0 3 1.0 2.0 9.0 0 100.75 host 0.5\r\n"
    "ROBOTLASER1 0 -1.0 2.0 0.5 8.0 0.01 0 2 3.0 4.0 1 55 0.0 1.0 1.5707963 0.0 0.0 "
    "1.5707963 0.1 0.2 0.3 0.4 0.5 101.0 host 0.75\n"
    "RLASER 2 1.0 90.0 0 0 3.14159 0 0 0 101.25 host 1.0";  // no final newline

TEST(CarmenSource, EveryLineKindWithItsOwnStampAndTheParams) {
    TempDir d;
    const auto v = readAll(d.write("a.clf", kLog));
    // ODOM; FLASER = odometry + scan; RAWLASER = scan; ROBOTLASER = odometry + scan; RLASER.
    ASSERT_EQ(v.size(), 8u);
    const Odo* odom = as<Odo>(v[0]);
    ASSERT_NE(odom, nullptr);
    EXPECT_NEAR(kfd::stampOf(*odom), 100.25, 1e-6);
    EXPECT_NEAR(odom->odometry.x(), 1.0, 1e-12);

    const Odo* fo = as<Odo>(v[1]);
    const Scan2D* f = as<Scan2D>(v[2]);
    ASSERT_TRUE(fo && f);
    EXPECT_EQ(f->sensorLabel, "FLASER");
    EXPECT_NEAR(kfd::stampOf(*f), 100.5, 1e-6);
    EXPECT_EQ(fo->timestamp, f->timestamp);
    EXPECT_NEAR(fo->odometry.phi(), 0.1, 1e-12);
    ASSERT_EQ(f->getScanSize(), 4u);
    EXPECT_NEAR(f->aperture, 4.0 * M_PI / 180.0, 1e-6);  // resolution x beams, as carmen2rawlog
    EXPECT_FLOAT_EQ(f->maxRange, 5.0f);
    EXPECT_TRUE(f->getScanRangeValidity(0));
    EXPECT_FALSE(f->getScanRangeValidity(1));  // 0: no return
    EXPECT_FALSE(f->getScanRangeValidity(2));  // at the max
    EXPECT_TRUE(f->getScanRangeValidity(3));
    // The laser pose (1.1, 2.0, 0.1) in the frame of the odometry pose (1.0, 2.0, 0.1).
    const double c = std::cos(0.1), s = std::sin(0.1);
    EXPECT_NEAR(f->sensorPose.x(), c * 0.1, 1e-9);
    EXPECT_NEAR(f->sensorPose.y(), -s * 0.1, 1e-9);
    EXPECT_NEAR(f->sensorPose.yaw(), 0.0, 1e-9);
    ASSERT_TRUE(v[2].odometry.has_value());
    EXPECT_NEAR(v[2].odometry->x, 1.0, 1e-12);

    const Scan2D* raw = as<Scan2D>(v[3]);
    ASSERT_NE(raw, nullptr);
    EXPECT_EQ(raw->sensorLabel, "RAWLASER1");
    EXPECT_FLOAT_EQ(raw->aperture, 3.0f);
    EXPECT_NEAR(raw->sensorPose.yaw(), 0.0, 1e-9);  // -1.5 + 3.0 / 2
    EXPECT_FALSE(raw->getScanRangeValidity(2));     // 9 > max 8
    EXPECT_NEAR(kfd::stampOf(*raw), 100.75, 1e-6);

    const Odo* ro = as<Odo>(v[4]);
    const Scan2D* rl = as<Scan2D>(v[5]);
    ASSERT_TRUE(ro && rl);
    EXPECT_NEAR(ro->odometry.y(), 0.0, 1e-9);
    EXPECT_NEAR(ro->odometry.phi(), M_PI / 2, 1e-6);
    // Laser (0, 1, 90 deg) from robot (0, 0, 90 deg): 1 m ahead; beams' middle at 0 rad.
    EXPECT_NEAR(rl->sensorPose.x(), 1.0, 1e-6);
    EXPECT_NEAR(rl->sensorPose.y(), 0.0, 1e-6);
    EXPECT_NEAR(rl->sensorPose.yaw(), 0.0, 1e-6);
    EXPECT_NEAR(kfd::stampOf(*rl), 101.0, 1e-6);

    const Scan2D* rear = as<Scan2D>(v[7]);
    ASSERT_NE(rear, nullptr);
    EXPECT_EQ(rear->sensorLabel, "RLASER");
    EXPECT_FLOAT_EQ(rear->maxRange, 81.0f);       // the front PARAMs are not the rear laser's
    EXPECT_FALSE(rear->getScanRangeValidity(1));  // 90 >= 81
}

TEST(CarmenSource, ParamOffsetsGiveTheMountAndGzipReadsLikePlain) {
    TempDir d;
    const std::string log =
        "PARAM robot_frontlaser_offset 0.2\nPARAM robot_frontlaser_side_offset -0.1\n"
        "FLASER 2 1 2 9 9 1 0 0 0 5.0 h 0\n";
    const auto plain = readAll(d.write("m.log", log));
    const auto gz = readAll(d.write("m.log.gz", log, true));
    ASSERT_EQ(plain.size(), 2u);
    ASSERT_EQ(gz.size(), 2u);
    const Scan2D* s = as<Scan2D>(plain[1]);
    ASSERT_NE(s, nullptr);
    EXPECT_NEAR(s->sensorPose.x(), 0.2, 1e-12);
    EXPECT_NEAR(s->sensorPose.y(), -0.1, 1e-12);
    EXPECT_EQ(as<Scan2D>(gz[1])->getScanRange(1), s->getScanRange(1));
    EXPECT_EQ(kfd::detectFormat(d / "m.log.gz"), kfd::LogFormat::Carmen);
    // No resolution PARAM: 361 beams are 0.5 deg each (carmen2rawlog's 180.5 deg aperture),
    // 180 beams 1 deg (180 deg, where a fixed 0.5 deg would give 90).
    auto flaser = [](std::size_t n) {
        std::string l = "FLASER " + std::to_string(n);
        for (std::size_t i = 0; i < n; ++i) l += " 1";
        return l + " 0 0 0 0 0 0 1.0 h 0\n";
    };
    EXPECT_NEAR(as<Scan2D>(readAll(d.write("361.clf", flaser(361)))[1])->aperture,
                180.5 * M_PI / 180, 1e-6);
    EXPECT_NEAR(as<Scan2D>(readAll(d.write("180.clf", flaser(180)))[1])->aperture, M_PI, 1e-6);
    EXPECT_EQ(kfd::detectFormat(d / "m.log"), kfd::LogFormat::Carmen);
}

std::string errorOf(const std::string& path) {
    try {
        readAll(path);
    } catch (const kfd::CarmenError& e) {
        return e.what();
    }
    return "no error";
}

TEST(CarmenSource, BadLinesNameTheFileTheLineAndTheField) {
    TempDir d;
    const std::string ok = "FLASER 2 1 2 0 0 0 0 0 0 5.0 h 0\n";
    const auto few = d.write("few.clf", ok + "FLASER 3 1 2 0 0 0 0 0 0 6.0 h 0\n");
    EXPECT_EQ(errorOf(few), few + ":2: FLASER with 3 readings has 13 fields, expected 14");
    const auto num = d.write("num.clf", ok + ok + "ODOM 1 two 3 0 0 0 7.0 h 0\n");
    EXPECT_EQ(errorOf(num), num + ":3: ODOM field 2 ('two') is not a number");
    const auto odom = d.write("odom.clf", "ODOM 1 2 3\n");
    EXPECT_EQ(errorOf(odom), odom + ":1: ODOM line has 4 fields, expected 10");
    const auto count = d.write("count.clf", "FLASER -2 1 2\n");
    EXPECT_NE(errorOf(count).find(count + ":1: FLASER reading count ('-2') is not a count"),
              std::string::npos);
    const auto raw = d.write("raw.clf", "RAWLASER1 0 -1.5 3.0 0.01 8.0 0.01 0 3 1.0 2.0\n");
    EXPECT_EQ(errorOf(raw),
              raw + ":1: RAWLASER1 reading count 3 is more than the 2 fields after it");
    const auto cut = d.write("cut.clf", "RAWLASER1 0 -1.5 3.0 0.01 8.0 0.01 0 2 1.0 2.0\n");
    EXPECT_EQ(errorOf(cut), cut + ":1: RAWLASER1 is cut short");
    const auto none = d.write("none.clf", "# only comments\nPARAM x 1\n");
    EXPECT_NE(errorOf(none).find("no laser or odometry lines"), std::string::npos);
    // A gzip log cut short: the error names the file and the last line read.
    std::string bytes = kfd::test::fileBytes(d.write("full.clf.gz", kLog + "\n" + kLog, true));
    const auto gz = d.write("cut.clf.gz", bytes.substr(0, bytes.size() - 6));
    const std::string e = errorOf(gz);
    EXPECT_EQ(e.rfind(gz + ": ", 0), 0u) << e;
    EXPECT_NE(e.find("gzip"), std::string::npos) << e;
}

// Counts are checked against the fields on their line before a scan is sized by them (issue
// 21): a reading count of 0x40000000 is an error naming it, not a 9.5 GB scan. Lines and
// their fields are bounded too (64 MiB, 2 000 100 fields), so no input makes the reader hold
// more than ~100 MB.
TEST(CarmenSource, CountsLinesAndFieldsAreBoundedBeforeAnythingIsAllocated) {
    TempDir d;
    const auto flaser = d.write("f.clf", "FLASER 1073741824 1 2 0 0 0 0 0 0 5.0 h 0\n");
    EXPECT_EQ(errorOf(flaser),
              flaser + ":1: FLASER reading count 1073741824 is more than the 11 fields after it");
    const auto rem =
        d.write("r.clf", "RAWLASER1 0 -1.5 3.0 0.01 8.0 0.01 0 2 1.0 2.0 4294967295 1 5.0 h 0\n");
    EXPECT_EQ(errorOf(rem),
              rem + ":1: RAWLASER1 remission count 4294967295 is more than the 4 fields after it");
    std::string many = "FLASER 1000001";
    for (int i = 0; i < 1000001 + 9; ++i) many += " 1";
    EXPECT_EQ(errorOf(d.write("m.clf", many + "\n")),
              d / "m.clf" + ":1: FLASER reading count 1000001 is more than 1000000");
    std::string fields = "ODOM";
    for (int i = 0; i < 2000100; ++i) fields += " 1";
    EXPECT_EQ(errorOf(d.write("w.clf", fields + "\n")),
              d / "w.clf" + ":1: more than 2000100 fields (not a CARMEN log?)");
    const auto line =
        d.write("l.clf", "ODOM 0 0 0 0 0 0 1.0 h 0\n" + std::string((64u << 20) + 1, 'x') + "\n");
    EXPECT_EQ(errorOf(line), line + ":2: a line longer than 64 MiB (not a CARMEN log?)");
    struct rusage u {};
    getrusage(RUSAGE_SELF, &u);
    EXPECT_LT(u.ru_maxrss, 512L * 1024L);  // KiB
}

// Bytes that are not text: every value but '\n', from a fixed seed.
std::string binary(std::size_t n, unsigned seed) {
    std::string b(n, '\0');
    for (auto& c : b) {
        seed = seed * 1103515245u + 12345u;
        c = static_cast<char>((seed >> 16) & 0xff);
        if (c == '\n' || c == '\r') c = '\0';
    }
    return b;
}

TEST(CarmenSource, LinesThatAreNotCarmenTextAreSkippedCountedAndMustNotDominate) {
    TempDir d;
    const std::string odom = "ODOM 1.0 2.0 0.1 0.0 0.0 0.0 100.25 host 0.0\n";
    const std::string bad1 = binary(300, 1) + "\n", bad2 = "hello 1 2 3\n",
                      bad3 = "# a comment with a control character \x01\n";
    const std::string text =
        "# caf\xc3\xa9: UTF-8 in a comment is fine\n" + odom + bad1 + odom + bad2 + bad3 + kLog;
    const auto mixed = d.write("mixed.clf", text);
    kfd::CarmenSource src(mixed);
    std::vector<SourceEntry> v;
    SourceEntry e;
    while (src.next(e)) v.push_back(e);
    const kfd::SourceCounters c = src.counters();
    EXPECT_EQ(c.lines_unparsable, 3u);
    EXPECT_EQ(c.first_unparsable_line, 3u);
    EXPECT_EQ(c.bytes_unparsable, bad1.size() + bad2.size() + bad3.size());
    // The other lines read as without them.
    const auto clean = readAll(d.write("clean.clf", odom + odom + kLog));
    ASSERT_EQ(v.size(), clean.size());
    for (std::size_t i = 0; i < v.size(); ++i)
        EXPECT_EQ(v[i].observation->GetRuntimeClass(), clean[i].observation->GetRuntimeClass());
    EXPECT_EQ(kfd::CarmenSource(d.write("c2.clf", kLog)).counters().lines_unparsable, 0u);
    // The listing counts them too.
    EXPECT_NE(kfd::listSource(mixed).detail.find(", 3 not CARMEN text)"), std::string::npos)
        << kfd::listSource(mixed).detail;
    // Where they outweigh the CARMEN lines, the log is refused (at its end).
    const auto mostly = d.write("mostly.clf", odom + binary(5000, 2) + "\n" + odom);
    EXPECT_EQ(errorOf(mostly), mostly +
                                   ": most of the log is not CARMEN text (binary data or another "
                                   "format?): 5001 of its " +
                                   std::to_string(5001 + 2 * odom.size()) +
                                   " bytes, in 1 line, the first at line 2");
}

TEST(CarmenSource, ALaserMountThatIsNotFiniteIsAnError) {
    TempDir d;
    const auto flaser = d.write("f.clf", "FLASER 2 1 2 nan 0 0 0 0 0 5.0 h 0\n");
    EXPECT_EQ(errorOf(flaser), flaser +
                                   ":1: FLASER laser pose (x y theta) or odometry (odom_x odom_y "
                                   "odom_theta) is not finite: the laser mount is unknown");
    const auto param = d.write("p.clf", "PARAM robot_frontlaser_offset inf\n");
    EXPECT_EQ(errorOf(param), param + ":1: PARAM robot_frontlaser_offset ('inf') is not finite");
    const auto raw =
        d.write("r.clf", "RAWLASER1 0 nan 3.0 0.01 8.0 0.01 0 3 1.0 2.0 9.0 0 1 h 0\n");
    EXPECT_EQ(errorOf(raw),
              raw +
                  ":1: RAWLASER1 start angle or field of view is not finite: the laser mount is "
                  "unknown");
}

TEST(LogFormat, TheContentDecides) {
    TempDir d;
    EXPECT_EQ(kfd::detectFormat(d.write("x.txt", "# c\n\nFLASER 1 1 0 0 0 0 0 0 1 h 0\n")),
              kfd::LogFormat::Carmen);
    EXPECT_EQ(kfd::detectFormat(d.write("y.clf", "# only a comment\n")), kfd::LogFormat::Carmen);
    EXPECT_EQ(kfd::detectFormat(d.write("z.rawlog", "not a rawlog\n")), kfd::LogFormat::Rawlog);
    EXPECT_EQ(kfd::detectFormat(d.write("b.dat", "#ROSBAG V2.0\n")), kfd::LogFormat::Bag);
    EXPECT_THROW(kfd::detectFormat(d / "missing.clf"), kfd::SourceError);
    EXPECT_EQ(kfd::openSource(d / "x.txt")->path(), d / "x.txt");
}

TEST(MitCsailClf, ReadDirectlyEqualsTheRawlogMadeFromIt) {
    const std::string clf = std::string(KFD_DATASETS_DIR) + "/mit-csail/mit-csail.clf";
    const std::string rawlog = std::string(KFD_DATASETS_DIR) + "/mit-csail/mit-csail.rawlog";
    if (!fs::exists(clf) || !fs::exists(rawlog)) GTEST_SKIP() << "dataset missing: " << clf;
    EXPECT_EQ(kfd::detectFormat(clf), kfd::LogFormat::Carmen);
    kfd::CarmenSource a(clf);
    kfd::RawlogSource b(rawlog);
    kfd::StreamFilter fa(kfd::kfdDefaults()), fb(kfd::kfdDefaults());
    SourceEntry ea, eb;
    std::size_t entries = 0, scans = 0, decisions_differ = 0;
    for (;;) {
        const bool na = a.next(ea), nb = b.next(eb);
        ASSERT_EQ(na, nb) << "entry " << entries;
        if (!na) break;
        ++entries;
        ASSERT_EQ(ea.kind, eb.kind);
        const auto* oa = as<Odo>(ea);
        const auto* ob = as<Odo>(eb);
        ASSERT_EQ(oa != nullptr, ob != nullptr) << entries;
        if (oa) {
            EXPECT_EQ(oa->sensorLabel, ob->sensorLabel);
            ASSERT_NEAR(oa->odometry.x(), ob->odometry.x(), 1e-9);
            ASSERT_NEAR(oa->odometry.y(), ob->odometry.y(), 1e-9);
            ASSERT_NEAR(oa->odometry.phi(), ob->odometry.phi(), 1e-9);
            continue;
        }
        auto sa = std::dynamic_pointer_cast<Scan2D>(ea.observation);
        auto sb = std::dynamic_pointer_cast<Scan2D>(eb.observation);
        ASSERT_TRUE(sa && sb);
        ++scans;
        EXPECT_EQ(sa->sensorLabel, sb->sensorLabel);
        // The rawlog's stamps came through MRPT's converter and its workaround (~1 us).
        ASSERT_NEAR(kfd::stampOf(*sa), kfd::stampOf(*sb), 2.5e-6);
        ASSERT_EQ(sa->getScanSize(), sb->getScanSize());
        EXPECT_EQ(sa->aperture, sb->aperture);
        EXPECT_EQ(sa->maxRange, sb->maxRange);
        EXPECT_NEAR(sa->sensorPose.x(), sb->sensorPose.x(), 1e-9);
        for (std::size_t k = 0; k < sa->getScanSize(); ++k) {
            ASSERT_EQ(sa->getScanRangeValidity(k), sb->getScanRangeValidity(k)) << scans;
            ASSERT_EQ(sa->getScanRange(k), sb->getScanRange(k));
        }
        decisions_differ += fa.process(*sa, ea.odometry).keep != fb.process(*sb, eb.odometry).keep;
    }
    EXPECT_EQ(scans, 1988u);
    EXPECT_EQ(decisions_differ, 0u);
}

}  // namespace
