// kfd/io/carmen_writer.h and kfd-filter's CARMEN output (issue 23): the lines on hand-made
// scans, and a filtered log written as .clf / .clf.gz that reads back, through kfd's CARMEN
// source and through MRPT's carmen2rawlog, as the scans kfd-filter kept.
#include <gtest/gtest.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "kfd/io/carmen_source.h"
#include "kfd/io/carmen_writer.h"
#include "kfd/io/open_source.h"
#include "kfd/io/rawlog_filter.h"
#include "kfd/io/rawlog_source.h"
#include "kfd/mrpt/config.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using Scan2D = mrpt::obs::CObservation2DRangeScan;
const std::string kOffice = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_carmen_writer_") {}
};

Scan2D scanOf(const std::string& label, std::vector<float> ranges, std::vector<bool> valid,
              double stamp) {
    Scan2D s;
    s.sensorLabel = label;
    s.aperture = static_cast<float>(M_PI);
    s.maxRange = 10.0f;
    s.rightToLeft = true;
    s.timestamp = mrpt::Clock::fromDouble(stamp);
    s.resizeScan(ranges.size());
    for (std::size_t i = 0; i < ranges.size(); ++i) {
        s.setScanRange(i, ranges[i]);
        s.setScanRangeValidity(i, valid[i]);
    }
    return s;
}

std::vector<std::string> dataLines(const std::string& path) {
    std::istringstream in(kfd::test::fileBytes(path));
    std::vector<std::string> v;
    for (std::string l; std::getline(in, l);)
        if (!l.empty() && l[0] != '#') v.push_back(l);
    return v;
}

// The 2D scans of a log, in order (their odometry is not compared: see the .clf test).
std::vector<std::shared_ptr<Scan2D>> scansOf(kfd::Source& src) {
    std::vector<std::shared_ptr<Scan2D>> v;
    kfd::SourceEntry e;
    while (src.next(e)) e.forEachScan([&](const auto& s) { v.push_back(s); });
    return v;
}

void expectSameScans(const std::vector<std::shared_ptr<Scan2D>>& a,
                     const std::vector<std::shared_ptr<Scan2D>>& b, double stamp_tol) {
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
        SCOPED_TRACE("scan " + std::to_string(k));
        const Scan2D &sa = *a[k], &sb = *b[k];
        ASSERT_EQ(sa.getScanSize(), sb.getScanSize());
        EXPECT_NEAR(kfd::stampOf(sa), kfd::stampOf(sb), stamp_tol);
        EXPECT_NEAR(sa.aperture, sb.aperture, 1e-6);
        EXPECT_EQ(sa.maxRange, sb.maxRange);
        EXPECT_NEAR(sa.sensorPose.x(), sb.sensorPose.x(), 1e-6);
        EXPECT_NEAR(sa.sensorPose.y(), sb.sensorPose.y(), 1e-6);
        EXPECT_NEAR(sa.sensorPose.yaw(), sb.sensorPose.yaw(), 1e-6);
        std::size_t valid_differ = 0, range_differ = 0;
        for (std::size_t i = 0; i < sa.getScanSize(); ++i) {
            const std::size_t j = sa.rightToLeft == sb.rightToLeft ? i : sa.getScanSize() - 1 - i;
            valid_differ += sa.getScanRangeValidity(i) != sb.getScanRangeValidity(j);
            range_differ += sa.getScanRangeValidity(i) && sa.getScanRange(i) != sb.getScanRange(j);
        }
        EXPECT_EQ(valid_differ, 0u);
        EXPECT_EQ(range_differ, 0u);  // valid ranges: the same floats
    }
}

kfd::RawlogFilterOptions filterOptions(const std::string& in, const std::string& out) {
    kfd::RawlogFilterOptions o;
    o.input = in;
    o.output = out;
    o.pipeline = kfd::kfdDefaults();
    return o;
}

}  // namespace

TEST(CarmenWriter, FlaserAndOdomLinesWithParamsInvalidBeamsAndTwoLasers) {
    TempDir d;
    const std::string f = d / "out.clf";
    kfd::CarmenWriter w(f, "", false, 6, "from a test");
    w.writeOdometry({1.0, 2.0, 0.5}, 100.25);
    // beams: valid 1.5, invalid (removed) 2.5, invalid beyond max, NaN
    const float nan = std::numeric_limits<float>::quiet_NaN();
    auto front = scanOf("LASER", {1.5f, 2.5f, 12.0f, nan}, {true, false, false, false}, 100.5);
    front.sensorPose = mrpt::poses::CPose3D(0.1, 0.0, 0.0, 0.0, 0.0, 0.0);
    w.writeScan(front, {1.0, 2.0, 0.0});
    auto rear = scanOf("BACK", {3.0f, 4.0f}, {true, true}, 100.75);
    rear.rightToLeft = false;  // written right to left: reversed
    w.writeScan(rear, {1.0, 2.0, 0.0});
    front.maxRange = 20.0f;  // a new max range: a new PARAM line
    w.writeScan(front, {1.0, 2.0, 0.0});
    EXPECT_THROW(w.writeScan(scanOf("THIRD", {1.0f}, {true}, 101.0), {0, 0, 0}),
                 kfd::CarmenWriteError);
    w.close();
    EXPECT_EQ(w.linesWritten(), 9u);
    const std::vector<std::string> expected{
        "ODOM 1 2 0.5 0 0 0 100.25 kfd 100.25",
        "PARAM robot_front_laser_max 10",
        "PARAM laser_front_laser_resolution 45",
        "FLASER 4 1.5 0 10 0 1.1 2 0 1 2 0 100.5 kfd 100.5",
        "PARAM robot_rear_laser_max 10",
        "PARAM laser_rear_laser_resolution 90",
        "RLASER 2 4 3 1 2 0 1 2 0 100.75 kfd 100.75",
        "PARAM robot_front_laser_max 20",
        "FLASER 4 1.5 0 0 0 1.1 2 0 1 2 0 100.5 kfd 100.5",
    };
    // The resolution is the float aperture over the beams: ~45 and ~90 deg.
    auto lines = dataLines(f);
    ASSERT_EQ(lines.size(), expected.size());
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const auto res = lines[i].find("_resolution ");
        if (res == std::string::npos) {
            EXPECT_EQ(lines[i], expected[i]);
            continue;
        }
        EXPECT_EQ(lines[i].substr(0, res), expected[i].substr(0, res));
        EXPECT_NEAR(std::stod(lines[i].substr(res + 12)), std::stod(expected[i].substr(res + 12)),
                    1e-5);
    }
    EXPECT_NE(kfd::test::fileBytes(f).find("# from a test\n"), std::string::npos);
    // kfd's CARMEN source reads the same beams back (0 and the max range: invalid).
    kfd::CarmenSource src(f);
    const auto back = scansOf(src);
    ASSERT_EQ(back.size(), 3u);
    EXPECT_EQ(back[0]->getScanRange(0), 1.5f);
    EXPECT_TRUE(back[0]->getScanRangeValidity(0));
    for (std::size_t i = 1; i < 4; ++i) EXPECT_FALSE(back[0]->getScanRangeValidity(i)) << i;
    EXPECT_NEAR(back[0]->sensorPose.x(), 0.1, 1e-9);
    EXPECT_NEAR(back[0]->aperture, M_PI, 1e-6);
    EXPECT_EQ(back[1]->getScanRange(0), 4.0f);
}

TEST(CarmenOutput, AFilteredLogWrittenAsClfReadsBackAsTheKeptScans) {
    TempDir d;
    const auto sr = kfd::RawlogFilter().run(filterOptions(kOffice, d / "out.rawlog"));
    const auto sc = kfd::RawlogFilter().run(filterOptions(kOffice, d / "out.clf"));
    EXPECT_EQ(sc.output_format, kfd::LogFormat::Carmen);
    EXPECT_EQ(sc.scans_kept, sr.scans_kept);
    ASSERT_GT(sc.scans_kept, 10u);
    EXPECT_EQ(kfd::detectFormat(d / "out.clf"), kfd::LogFormat::Carmen);
    const auto text = kfd::test::fileBytes(d / "out.clf");
    EXPECT_EQ(text.rfind("# CARMEN log written by kfd\n", 0), 0u);
    // FLASER for every kept scan, ODOM for each odometry reading, stamps in order.
    std::size_t flaser = 0, odom = 0;
    double last = -1.0;
    for (const auto& l : dataLines(d / "out.clf")) {
        std::istringstream in(l);
        std::string kw;
        in >> kw;
        flaser += kw == "FLASER";
        odom += kw == "ODOM";
        if (kw == "PARAM") continue;
        std::vector<std::string> f{std::istream_iterator<std::string>(in), {}};
        const double t = std::stod(f[f.size() - 3]);
        EXPECT_GE(t, last) << l.substr(0, 40);
        last = t;
    }
    EXPECT_EQ(flaser, sc.scans_kept);
    EXPECT_EQ(odom, 600u);  // the office log's odometry readings
    kfd::RawlogSource kept(d / "out.rawlog");
    kfd::CarmenSource back(d / "out.clf");
    expectSameScans(scansOf(kept), scansOf(back), 1e-6);

    // gzip: the same lines.
    kfd::RawlogFilter().run(filterOptions(kOffice, d / "out.clf.gz"));
    kfd::CarmenSource gz(d / "out.clf.gz");
    kfd::CarmenSource plain(d / "out.clf");
    expectSameScans(scansOf(plain), scansOf(gz), 0.0);
}

TEST(CarmenOutput, MrptCarmen2rawlogReadsTheClf) {
    if (!fs::exists("/usr/bin/carmen2rawlog")) GTEST_SKIP() << "no /usr/bin/carmen2rawlog";
    TempDir d;
    kfd::RawlogFilter().run(filterOptions(kOffice, d / "out.clf"));
    const std::string cmd = "cd '" + d.path.string() +
                            "' && /usr/bin/carmen2rawlog -q -w -i out.clf -o conv.rawlog "
                            ">/dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    kfd::CarmenSource ours(d / "out.clf");
    kfd::RawlogSource theirs(d / "conv.rawlog");
    // carmen2rawlog shifts every stamp (its own log start): stamps are not compared.
    expectSameScans(scansOf(ours), scansOf(theirs), 1e12);
}

TEST(CarmenOutput, AnOutputNameOfNoFormatKfdWritesIsRefused) {
    TempDir d;
    for (const char* name : {"y.txt", "y.rawlog.txt", "y"}) {
        try {
            kfd::RawlogFilter().run(filterOptions(kOffice, d / name));
            ADD_FAILURE() << name << ": no error";
        } catch (const kfd::RawlogError& e) {
            EXPECT_EQ(std::string(e.what()),
                      "the output " + (d / name) +
                          ": kfd-filter writes .rawlog (an MRPT rawlog), .bag (a ROS 1 bag, for "
                          "a ROS 1 bag input), .db3 or .mcap (ROS 2, for any bag input), .clf "
                          "or .log (a CARMEN log; .clf.gz, .log.gz: gzip); "
                          "its name says none of them");
        }
        EXPECT_FALSE(fs::exists(d / name));
    }
    EXPECT_TRUE(fs::is_empty(d.path));
}

TEST(CarmenOutput, ALogWithoutOdometryIsRefusedAndLeavesNothing) {
    TempDir d;
    // A CARMEN log of RAWLASER lines: scans without odometry.
    const std::string in = d / "scans.clf";
    {
        kfd::CarmenWriter w(in, "", false);  // FLASER lines need odometry: RAWLASER has none
        w.close();
    }
    std::ofstream(in, std::ios::app)
        << "RAWLASER1 0 -1.57 3.14 0.0174 8 0.01 0 3 1 2 3 0 10.0 host 0\n"
           "RAWLASER1 0 -1.57 3.14 0.0174 8 0.01 0 3 1 2 3 0 10.5 host 0\n";
    try {
        kfd::RawlogFilter().run(filterOptions(in, d / "out.clf"));
        ADD_FAILURE() << "no error";
    } catch (const kfd::RawlogError& e) {
        EXPECT_NE(std::string(e.what()).find("a CARMEN output needs the robot's odometry"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(d / "out.clf"));
    kfd::RawlogFilter().run(filterOptions(in, d / "out.rawlog"));  // a rawlog takes it
    EXPECT_TRUE(fs::exists(d / "out.rawlog"));
}
