// Every bad log a clear error or a counted repair: non-finite mounts, CARMEN garbage, logs with
// no usable scan, LaserScan angles, stamps and odometry, MRPT's exceptions.
#include "app_runner.h"
#include "bad_logs.h"

namespace {

using namespace kfd::test::apps;

// --- every bad input a clear error or a counted repair (issue 21, item 4) ---

// kfd-filter and kfd-icp-slam on a log they repair: exit 0, the repair counted in kfd-filter's
// summary (`line`) and in summary.json (`json`), the input unchanged. Returns kfd-filter's stdout.
std::string expectLogRepaired(const Dir& d, const std::string& in, const std::string& line,
                              const std::string& json, const std::string& out = "out.bag") {
    SCOPED_TRACE(in + " " + line);
    const Snapshot snap({in});
    const Result r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / out}, d.path);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    if (!line.empty()) {
        EXPECT_NE(r.out.find("\n" + line + "\n"), std::string::npos) << r.out;
    }
    EXPECT_TRUE(fs::exists(d / out));
    const Result s =
        run(KFD_ICP_SLAM_EXE, {kSlamIni, in, "-o", d / "slam", "-q", "--no-map"}, d.path);
    EXPECT_EQ(s.status, 0) << s.err;
    const std::string summary = fileBytes(d / "slam/summary.json");
    EXPECT_NE(summary.find(json), std::string::npos) << summary;
    fs::remove(d / out);
    fs::remove_all(d / "slam");
    snap.expectUnchanged();
    return r.out;
}

// 40 scans of writeBag's room; `tweak(k, scan)` changes scan k, `bag_time(k)` its record time
// (its stamp when negative); odometry at `odom_t0 + 0.2 k`.
std::string writeBagWith(const Dir& d, const std::string& name,
                         const std::function<void(int, sensor_msgs::LaserScan&)>& tweak,
                         double odom_t0 = 1.0) {
    const std::string p = d / name;
    kfd::test::BagBuilder b(p);
    for (int i = 0; i < 40; ++i) {
        b.odom("/odom", odom_t0 + 0.2 * i, 0.05 * i, 0, 0);
        std::vector<float> r(181);
        for (std::size_t k = 0; k < r.size(); ++k) r[k] = 2.0f + 0.01f * static_cast<float>(k % 7);
        auto m = kfd::test::BagBuilder::scanMsg(1 + 0.2 * i + 0.1, r);
        tweak(i, m);
        b.scan("/scan", m, 1 + 0.2 * i + 0.1);
    }
    return p;
}

TEST(RepairedOrRefusedLogs, ANonFiniteLaserMountIsAnErrorNamingTheFrame) {
    Dir d;
    const std::string bag = d / "mount.bag";
    {
        kfd::test::BagBuilder b(bag);
        b.tf("/tf_static", 1, "base_link", "laser", std::nan(""), 0, 0);
        for (int i = 0; i < 10; ++i) {
            b.odom("/odom", 1 + 0.2 * i, 0.05 * i, 0, 0);
            b.scan("/scan",
                   kfd::test::BagBuilder::scanMsg(1.1 + 0.2 * i, std::vector<float>(181, 2)));
        }
    }
    expectLogRefused(d, bag, {},
                     bag +
                         ": the laser mount of frame 'laser' (base_link -> laser in /tf_static) "
                         "is not usable: the transform base_link -> laser: its translation "
                         "(nan, 0, 0) is not finite");
    // A rawlog scan's sensor pose, a CARMEN laser pose: the same rule, the object or line named.
    const std::string rawlog = d / "mount.rawlog";
    kfd::test::writeRoomLog(rawlog, 10, [](int k, mrpt::obs::CObservation2DRangeScan& s) {
        if (k == 3) s.sensorPose = mrpt::poses::CPose3D(0, 0, 0, std::nan(""), 0, 0);
    });
    expectLogRefused(d, rawlog, {},
                     rawlog +
                         ": object #7: the laser mount (sensor pose) of scan 'LASER' is not "
                         "finite",
                     "out.rawlog");
    const auto clf = d.write("mount.clf",
                             "FLASER 3 1 2 3 0 0 0 0 0 0 5.0 h 0\n"
                             "FLASER 3 1 2 3 0 inf 0 0 0 0 5.2 h 0\n");
    expectLogRefused(d, clf, {},
                     clf +
                         ":2: FLASER laser pose (x y theta) or odometry (odom_x odom_y "
                         "odom_theta) is not finite: the laser mount is unknown",
                     "out.rawlog");
}

// A CARMEN log of `n` FLASER lines (bad_logs.h's room walk, 361 beams) after a comment line.
std::string carmenRoom(int n) {
    std::string s = "# kfd test log\n";
    char buf[128];
    for (int k = 0; k < n; ++k) {
        mrpt::obs::CObservation2DRangeScan scan;
        kfd::test::roomScanInto(scan, 0.05 * k, 0.0);
        s += "FLASER 361";
        for (std::size_t i = 0; i < scan.getScanSize(); ++i) {
            std::snprintf(buf, sizeof(buf), " %.3f", scan.getScanRange(i));
            s += buf;
        }
        const double x = 0.05 * k, t = 1000.0 + 0.2 * k;
        std::snprintf(buf, sizeof(buf), " %.3f 0 0 %.3f 0 0 %.3f host %.3f\n", x, x, t, t);
        s += buf;
    }
    return s;
}

// `n` bytes of binary data (every byte value, line ends included, no empty line) from a fixed
// seed, starting with a byte that is no line end and ending with one.
std::string garbage(std::size_t n) {
    std::string g(n, '\0');
    unsigned seed = 21;
    for (std::size_t i = 0; i < n; ++i) {
        seed = seed * 1103515245u + 12345u;
        g[i] = static_cast<char>((seed >> 16) & 0xff);
        if (i > 0 && g[i] == '\n' && g[i - 1] == '\n') g[i] = '\x01';
    }
    g.front() = '\x01';
    g.back() = '\n';
    return g;
}

TEST(RepairedOrRefusedLogs, CarmenBinaryGarbageIsCountedAndRefusedWhereItDominates) {
    Dir d;
    const std::string head = carmenRoom(50), tail = carmenRoom(100).substr(head.size());
    const auto clean = d.write("clean.clf", head + tail);
    const auto dirty = d.write("dirty.clf", head + garbage(60000) + tail);
    ASSERT_LT(60000u, (head + tail).size());
    // Counted, reported, and the output is the clean log's.
    const std::string out = expectLogRepaired(d, dirty, "", "\"lines_unparsable\": ", "x.rawlog");
    const std::string prefix = "\n  unparsed ";
    const auto at = out.find(prefix);
    ASSERT_NE(at, std::string::npos) << out;
    const std::string line = out.substr(at + 1, out.find('\n', at + 1) - at - 1);
    EXPECT_NE(line.find(" lines that are not CARMEN text skipped (60000 bytes, the first at line "
                        "52)"),
              std::string::npos)
        << line;
    Result r = run(KFD_FILTER_EXE, {"-q", "-i", clean, "-o", d / "clean.rawlog"}, d.path);
    ASSERT_EQ(r.status, 0) << r.err;
    r = run(KFD_FILTER_EXE, {"-q", "-i", dirty, "-o", d / "dirty.rawlog"}, d.path);
    ASSERT_EQ(r.status, 0) << r.err;
    auto decoded = [](const std::string& p) {
        mrpt::io::CFileGZInputStream in(p);
        std::string bytes, buf(1 << 16, '\0');
        while (const std::size_t n = in.Read(buf.data(), buf.size())) bytes.append(buf.data(), n);
        return bytes;
    };
    EXPECT_TRUE(decoded(d / "clean.rawlog") == decoded(d / "dirty.rawlog"));
    EXPECT_EQ(run(KFD_FILTER_EXE, {"-q", "-i", clean, "-o", d / "c2.rawlog"}, d.path)
                  .out.find("unparsed"),
              std::string::npos);  // a clean log: no such line
    fs::remove(d / "clean.rawlog");
    fs::remove(d / "dirty.rawlog");
    fs::remove(d / "c2.rawlog");
    // Where the garbage outweighs the CARMEN lines: an error, nothing written.
    const auto mostly = d.write("mostly.clf", carmenRoom(5) + garbage(60000));
    expectLogRefused(
        d, mostly, {},
        mostly + ": most of the log is not CARMEN text (binary data or another format?): ",
        "out.rawlog");
}

TEST(RepairedOrRefusedLogs, ARunWithNoUsableScanFailsAndWritesNothing) {
    Dir d;
    const std::string odometry = d / "odometry.rawlog";
    {
        mrpt::io::CFileGZOutputStream f(odometry);
        auto arch = mrpt::serialization::archiveFrom(f);
        for (int k = 0; k < 10; ++k) {
            mrpt::obs::CObservationOdometry o;
            o.timestamp = mrpt::Clock::fromDouble(1000.0 + 0.2 * k);
            o.odometry = mrpt::poses::CPose2D(0.05 * k, 0, 0);
            arch << o;
        }
    }
    expectLogRefused(d, odometry, {}, "no laser scan in " + odometry, "out.rawlog");
    const std::string skipped = d / "skipped.rawlog";
    kfd::test::writeRoomLog(skipped, 5,
                            [](int, mrpt::obs::CObservation2DRangeScan& s) { s.aperture = 0; });
    expectLogRefused(d, skipped, {},
                     "no usable scan in " + skipped +
                         ": all 5 scans skipped (bad_aperture 5: an aperture that is not finite, "
                         "<= 0 or above 2 pi)",
                     "out.rawlog");
    const auto clf =
        d.write("odometry.clf", "ODOM 1 2 0 0 0 0 5.0 h 0\nODOM 1 2 0 0 0 0 5.2 h 0\n");
    expectLogRefused(d, clf, {}, "no laser scan in " + clf, "out.rawlog");
    const auto bag = writeBagWith(d, "angles.bag", [](int, sensor_msgs::LaserScan& m) {
        m.angle_increment = -m.angle_increment;
    });
    expectLogRefused(d, bag, {},
                     "no usable scan in " + bag +
                         ": all 40 scans skipped (bad_aperture 40: an aperture that is not "
                         "finite, <= 0 or above 2 pi; of them 40 LaserScans whose angle fields do "
                         "not match their beam count)");
    // kfd-icp-slam skipping every scan at the start.
    const std::string room = d / "room.rawlog";
    kfd::test::writeRoomLog(room, 10);
    const auto before = listing(d.path);
    const Snapshot snap({room});
    const Result r =
        run(KFD_ICP_SLAM_EXE,
            {kSlamIni, room, "-o", d / "slam", "-q", "--no-map", "--skip-scans", "100"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-icp-slam: no laser scan in " + room +
                             " after the 10 skipped at its start (skip_scans = 100)");
    EXPECT_EQ(listing(d.path), before);
    snap.expectUnchanged();
}

TEST(RepairedOrRefusedLogs, LaserScanAnglesStampsAndOdometryAreCountedRepairs) {
    Dir d;
    // Angle fields that do not match the beam count: a counted skip (the scan was mirrored).
    const auto angles = writeBagWith(d, "angles.bag", [](int k, sensor_msgs::LaserScan& m) {
        if (k % 10 == 3) m.angle_increment = k == 3 ? std::nanf("") : -m.angle_increment;
    });
    const std::string out = expectLogRepaired(
        d, angles,
        "  angles   4 LaserScans whose angle fields do not match their beam count (skipped: "
        "bad_aperture)",
        "\"scans_bad_angles\": 4");
    EXPECT_NE(out.find("\n  skipped  4 (bad geometry, dropped from the output): bad_aperture 4\n"),
              std::string::npos)
        << out;
    // Header stamps of 0: the bag time, counted; the odometry still found for every scan.
    const auto zero = writeBagWith(
        d, "zero.bag", [](int, sensor_msgs::LaserScan& m) { m.header.stamp = ros::Time(); });
    const std::string z =
        expectLogRepaired(d, zero, "  stamps   40 messages stamped 0 (unset): their bag time used",
                          "\"stamps_zero\": 40");
    EXPECT_NE(z.find(", odometry\n"), std::string::npos) << z;
    // Odometry that never brackets the scans: no odometry for them, counted (not the first
    // sample for every scan).
    const auto late = writeBagWith(
        d, "late.bag", [](int, sensor_msgs::LaserScan&) {}, 100.0);
    const std::string l = expectLogRepaired(
        d, late,
        "  odometry 40 scans more than 1 s outside the odometry's time span: no odometry for them",
        "\"scans_without_odometry\": 40");
    EXPECT_NE(l.find("no odometry (laser only)"), std::string::npos) << l;
}

#ifdef KFD_RENDER_EXE
TEST(RepairedOrRefusedLogs, RenderChecksTheScanThroughTheDoor) {
    Dir d;
    const std::string in = d / "bad.rawlog";
    kfd::test::writeRoomLog(in, 30, [](int k, mrpt::obs::CObservation2DRangeScan& s) {
        if (k == 6) s.resizeScan(0);
        if (k == 8) s.aperture = std::nanf("");
    });
    const Snapshot snap({in});
    Result r = run(KFD_RENDER_EXE, {"-i", in, "--index", "6", "-o", d / "x.png"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-render: scan 6 of " + in +
                             " (t = 1001.200000 s) cannot be drawn: it has fewer than 2 beams "
                             "(no_beams)");
    r = run(KFD_RENDER_EXE, {"-i", in, "--time", "1001.6", "-o", d / "x.png"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-render: scan 8 of " + in +
                             " (t = 1001.600000 s) cannot be drawn: it has an aperture that is not "
                             "finite, <= 0 or above 2 pi (bad_aperture)");
    r = run(KFD_RENDER_EXE, {"-i", in, "--index", "30", "-o", d / "x.png"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(),
              "kfd-render: no scan 30 in " + in + ": it holds 30 2D scans (--index counts from 0)");
    EXPECT_EQ(listing(d.path), std::set<std::string>{"bad.rawlog"});
    // A bad scan among the history scans is no previous keyframe: the chosen one is drawn.
    r = run(KFD_RENDER_EXE, {"-i", in, "--index", "7", "-o", d / "x.png"}, d.path);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"bad.rawlog", "x.png"}));
    snap.expectUnchanged();
}
#endif

TEST(RepairedOrRefusedLogs, AnMrptExceptionSaysWhatIsWrongOnItsFirstLine) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    std::string ini = fileBytes(kSlamIni);
    const auto at = ini.find("ICP_algorithm = icpClassic");
    ASSERT_NE(at, std::string::npos);
    ini.replace(at, 26, "ICP_algorithm = icpFancy");
    const auto cfg = d.write("slam.ini", ini);
    const Snapshot snap({in, cfg});
    const Result r = run(KFD_ICP_SLAM_EXE, {"-q", cfg, in, "-o", d / "out"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-icp-slam: the configuration " + cfg +
                             " ([MappingApplication], [ICP]): Invalid value 'icpFancy' for enum "
                             "type while reading key='ICP_algorithm'.");
    EXPECT_EQ(r.err.find("MRPT exception"), std::string::npos) << r.err;  // no banner, no stack
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"in.rawlog", "slam.ini"}));
    snap.expectUnchanged();
}

}  // namespace
