// The ROS 1 bag source and writer: tiny hand-made bags (odometry interpolation, /tf odometry,
// the /tf_static mount, the beam validity rule, topic choices, compression, bad bags), a
// filtered bag read back, and the Freiburg bags against their rawlogs.
#include <gtest/gtest.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <rosbag/view.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>

#include "kfd/io/bag_source.h"
#include "kfd/io/bag_writer.h"
#include "kfd/io/open_source.h"
#include "kfd/io/rawlog_filter.h"
#include "kfd/io/rawlog_source.h"
#include "kfd/io/source_listing.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/stages/core_stages.h"
#include "test_bags.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using kfd::SourceEntry;
using kfd::test::BagBuilder;
using Kind = kfd::SourceEntry::Kind;
using Scan2D = mrpt::obs::CObservation2DRangeScan;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_bag_") {}
};

std::vector<SourceEntry> readAll(const std::string& path, const kfd::SourceOptions& o = {}) {
    kfd::BagSource src(path, o);
    std::vector<SourceEntry> v;
    SourceEntry e;
    while (src.next(e)) v.push_back(e);
    return v;
}

std::vector<Scan2D::Ptr> scansOf(const std::vector<SourceEntry>& v) {
    std::vector<Scan2D::Ptr> s;
    for (const auto& e : v) e.forEachScan([&](const Scan2D::Ptr& p) { s.push_back(p); });
    return s;
}

using kfd::test::room;

TEST(BagSource, ScansGetInterpolatedOdometryTheStaticMountAndTheValidityRule) {
    TempDir d;
    {
        BagBuilder b(d / "a.bag");
        b.tf("/tf_static", 0.5, "base_link", "mount", 0.1, 0.0, 0.0);
        b.tf("/tf_static", 0.5, "mount", "laser", 0.05, 0.0, M_PI / 2);
        b.odom("/odom", 0.9, 1.0, 0.0, 0.0);
        auto m = BagBuilder::scanMsg(1.0, {1.0f, kNaN, kInf, 0.05f, 10.0f, 2.0f}, "/laser", -1.0f,
                                     2.0f, 0.1f, 10.0f);
        m.intensities = {10, 20, 30, 40, 50, 60};
        b.scan("/scan", m);
        b.odom("/odom", 1.1, 2.0, 1.0, 0.2);
        b.odom("/odom", 2.0, 3.0, 1.0, 0.3);
        // Recorded after its stamp (bag time 2.01): the odometry at 2.0 came first.
        b.scan("/scan", BagBuilder::scanMsg(2.0, {1, 2, 3, 4, 5, 6}, "laser", -1.0f, 2.0f), 2.01);
        b.odom("/odom", 3.0, 4.0, 1.0, 0.4);
        b.scan("/scan", BagBuilder::scanMsg(3.5, {1, 2, 3, 4, 5, 6}, "laser", -1.0f, 2.0f));
    }
    kfd::BagSource src(d / "a.bag");
    EXPECT_EQ(src.choice().scan_topic, "/scan");
    EXPECT_EQ(src.choice().odometry, kfd::BagChoice::Odometry::Topic);
    EXPECT_EQ(src.choice().base_frame, "base_link");
    EXPECT_EQ(src.choice().laser_frame, "laser");  // the leading '/' is ignored
    ASSERT_TRUE(src.choice().mount_found);
    EXPECT_NEAR(src.choice().mount_x, 0.15, 1e-12);
    EXPECT_NEAR(src.choice().mount_yaw, M_PI / 2, 1e-12);

    std::vector<SourceEntry> v;
    SourceEntry e;
    while (src.next(e)) v.push_back(e);
    // The bag's order; each scan preceded by its odometry observation.
    const std::vector<Kind> kinds{Kind::Native,      Kind::Native,      Kind::Native,
                                  Kind::Observation, Kind::Observation, Kind::Native,
                                  Kind::Native,      Kind::Observation, Kind::Observation,
                                  Kind::Native,      Kind::Observation, Kind::Observation};
    ASSERT_EQ(v.size(), kinds.size());
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i].kind, kinds[i]) << i;
    const auto scans = scansOf(v);
    ASSERT_EQ(scans.size(), 3u);
    const Scan2D& s = *scans[0];
    EXPECT_EQ(s.sensorLabel, "scan");
    EXPECT_NEAR(kfd::stampOf(s), 1.0, 1e-6);
    EXPECT_FLOAT_EQ(s.aperture, 3.0f);
    EXPECT_TRUE(s.rightToLeft);
    EXPECT_FLOAT_EQ(s.maxRange, 10.0f);
    EXPECT_NEAR(s.sensorPose.x(), 0.15, 1e-9);
    EXPECT_NEAR(s.sensorPose.yaw(), M_PI / 2 + 0.5, 1e-6);  // mount + the beams' middle
    const std::vector<bool> valid{true,  false, false,
                                  false, false, true};  // NaN, inf, < min, = max
    for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(s.getScanRangeValidity(i), valid[i]) << i;
    EXPECT_FLOAT_EQ(s.getScanRange(1), 0.0f);  // non-finite stored as 0
    ASSERT_TRUE(s.hasIntensity());
    EXPECT_EQ(s.getScanIntensity(5), 60);
    // 1.0 lies halfway between the odometry at 0.9 and 1.1.
    ASSERT_TRUE(v[4].odometry.has_value());
    EXPECT_NEAR(v[4].odometry->x, 1.5, 1e-9);
    EXPECT_NEAR(v[4].odometry->y, 0.5, 1e-9);
    EXPECT_NEAR(v[4].odometry->phi, 0.1, 1e-9);
    const auto* odo = dynamic_cast<const mrpt::obs::CObservationOdometry*>(v[3].observation.get());
    ASSERT_NE(odo, nullptr);
    EXPECT_NEAR(odo->odometry.x(), 1.5, 1e-9);
    EXPECT_EQ(odo->timestamp, s.timestamp);
    EXPECT_NE(v[4].native, nullptr);  // the original LaserScan travels with the scan
    // Exactly at an odometry stamp: that message; after the last one: the last one held.
    EXPECT_NEAR(v[7].odometry->x, 3.0, 1e-9);
    EXPECT_NEAR(v[11].odometry->x, 4.0, 1e-9);
}

TEST(BagSource, OdometryComesFromTfWhenTheBagHasNoOdometryTopic) {
    TempDir d;
    {
        BagBuilder b(d / "tf.bag");
        b.tf("/tf", 1.0, "odom", "base_footprint", 1.0, 2.0, 0.5);
        b.tf("/tf", 1.0, "base_footprint", "laser", 0.3, 0.0, 0.0);  // not odometry
        b.scan("/scan", BagBuilder::scanMsg(1.0, room(0, 0, 0, 50)));
        b.tf("/tf", 2.0, "odom", "base_footprint", 2.0, 2.0, 0.5);
    }
    kfd::BagSource src(d / "tf.bag");
    EXPECT_EQ(src.choice().odometry, kfd::BagChoice::Odometry::Tf);
    EXPECT_EQ(src.choice().base_frame, "base_footprint");
    std::vector<SourceEntry> v;
    SourceEntry e;
    while (src.next(e)) v.push_back(e);
    const auto it = std::find_if(v.begin(), v.end(), [](const SourceEntry& x) {
        return std::dynamic_pointer_cast<Scan2D>(x.observation) != nullptr;
    });
    ASSERT_NE(it, v.end());
    ASSERT_TRUE(it->odometry.has_value());
    EXPECT_NEAR(it->odometry->x, 1.0, 1e-9);
    EXPECT_NEAR(it->odometry->phi, 0.5, 1e-9);
    // --odom-topic none: laser only.
    kfd::SourceOptions o;
    o.odom_topic = "none";
    for (const auto& x : readAll(d / "tf.bag", o)) EXPECT_FALSE(x.odometry.has_value());
}

TEST(BagSource, ALaserOnlyBagGivesScansWithoutOdometry) {
    TempDir d;
    {
        BagBuilder b(d / "l.bag");
        for (int i = 1; i <= 3; ++i) b.scan("/scan", BagBuilder::scanMsg(i, room(0, 0, 0, 20)));
    }
    const auto v = readAll(d / "l.bag");
    ASSERT_EQ(v.size(), 3u);  // no odometry observations
    for (const auto& e : v) {
        EXPECT_EQ(e.kind, Kind::Observation);
        EXPECT_FALSE(e.odometry.has_value());
    }
}

TEST(BagSource, ANonFiniteStaticMountIsAnErrorNamingTheFrames) {
    TempDir d;
    const double nan = std::nan("");
    auto errorOf = [&](const std::string& name, double x, double yaw, bool on_chain) {
        {
            BagBuilder b(d / name);
            b.tf("/tf_static", 0.5, "base_link", "mount", x, 0.0, yaw);
            b.tf("/tf_static", 0.5, on_chain ? "mount" : "base_link", on_chain ? "laser" : "other",
                 0.05, 0.0, 0.0);
            b.tf("/tf_static", 0.5, "base_link", "camera", nan, 0.0, 0.0);  // not the laser's
            b.odom("/odom", 0.9, 0.0, 0.0, 0.0);
            b.scan("/scan", BagBuilder::scanMsg(1.0, room(0, 0, 0, 20)));
        }
        try {
            kfd::BagSource src(d / name);
            return std::string("no error, mount found: ") +
                   (src.choice().mount_found ? "yes" : "no");
        } catch (const kfd::BagError& e) {
            return std::string(e.what());
        }
    };
    EXPECT_EQ(errorOf("x.bag", nan, 0.0, true),
              (d / "x.bag") +
                  ": the laser mount of frame 'laser' (base_link -> laser in /tf_static) is not "
                  "usable: the transform base_link -> mount: its translation (nan, 0, 0) is not "
                  "finite");
    EXPECT_NE(errorOf("yaw.bag", 0.1, nan, true)
                  .find("the transform base_link -> mount: its "
                        "rotation (quaternion 0, 0, nan, nan) is "
                        "not finite"),
              std::string::npos);
    // A NaN transform off the laser's chain (the camera's) changes nothing.
    EXPECT_EQ(errorOf("off.bag", 0.1, 0.0, false), "no error, mount found: no");
    // The listing says why it cannot be used instead of throwing.
    const auto l = kfd::listSource(d / "x.bag");
    ASSERT_FALSE(l.choices.empty());
    EXPECT_NE(l.choices.back().find("cannot use as it is: the laser mount of frame 'laser'"),
              std::string::npos)
        << l.choices.back();
}

// --list's first line: "1 topic, 1 message", not "1 topics, 1 messages" (issue 23).
TEST(BagSource, TheListingCountsTopicsAndMessagesInTheRightNumber) {
    TempDir d;
    {
        BagBuilder b(d / "one.bag");
        b.scan("/scan", BagBuilder::scanMsg(1.0, room(0, 0, 0, 20)));
    }
    EXPECT_EQ(kfd::listSource(d / "one.bag").detail, "ROS 1 bag, 1 topic, 1 message");
    {
        BagBuilder b(d / "two.bag");
        b.scan("/scan", BagBuilder::scanMsg(1.0, room(0, 0, 0, 20)));
        b.scan("/scan", BagBuilder::scanMsg(2.0, room(0, 0, 0, 20)));
    }
    EXPECT_EQ(kfd::listSource(d / "two.bag").detail, "ROS 1 bag, 1 topic, 2 messages");
}

TEST(BagSource, AnglesThatDoNotMatchTheBeamCountAreSkippedAndCounted) {
    TempDir d;
    {
        BagBuilder b(d / "a.bag");
        auto msg = [&](double t) { return BagBuilder::scanMsg(t, room(0, 0, 0, 20)); };
        b.scan("/scan", msg(1.0));  // good: 19 increments over the span
        auto m = msg(2.0);
        m.angle_increment = kNaN;
        b.scan("/scan", m);
        m = msg(3.0);
        m.angle_increment = -m.angle_increment;  // mirrored the scan before
        b.scan("/scan", m);
        m = msg(4.0);
        m.angle_increment /= 2;  // the span holds 39 increments, not 19
        b.scan("/scan", m);
        m = msg(5.0);
        m.angle_max = kInf;
        b.scan("/scan", m);
        m = msg(6.0);
        // n increments (angle_max one increment past the last beam, as 360-degree drivers give
        // it): the beams span n - 1 increments.
        m.angle_increment = (m.angle_max - m.angle_min) / 20;
        b.scan("/scan", m);
    }
    kfd::BagSource src(d / "a.bag");
    std::vector<SourceEntry> v;
    SourceEntry e;
    while (src.next(e)) v.push_back(e);
    const auto scans = scansOf(v);
    ASSERT_EQ(scans.size(), 6u);
    kfd::StreamFilter door;
    std::vector<kfd::ScanSkipReason> skipped;
    for (const auto& s : scans) {
        EXPECT_TRUE(std::isfinite(s->sensorPose.yaw()));
        skipped.push_back(door.process(*s).skipped);
    }
    using R = kfd::ScanSkipReason;
    EXPECT_EQ(skipped, (std::vector<R>{R::None, R::BadAperture, R::BadAperture, R::BadAperture,
                                       R::BadAperture, R::None}));
    EXPECT_EQ(src.counters().scans_bad_angles, 4u);
    EXPECT_TRUE(scans[0]->rightToLeft);
    EXPECT_FLOAT_EQ(scans[5]->aperture, 3.0f * 19 / 20);
}

TEST(BagSource, ZeroStampsTakeTheBagTimeAndOdometryIsHeldOneSecondAtMost) {
    TempDir d;
    {
        BagBuilder b(d / "s.bag");
        b.scan("/scan", BagBuilder::scanMsg(3.0, room(0, 0, 0, 20)));  // 2 s before the odometry
        b.scan("/scan", BagBuilder::scanMsg(4.5, room(0, 0, 0, 20)));  // 0.5 s before: held
        b.odom("/odom", 5.0, 1.0, 0.0, 0.0);
        b.scan("/scan", BagBuilder::scanMsg(0.0, room(0, 0, 0, 20)), 5.5);  // stamp 0: bag time
        b.odom("/odom", 6.0, 2.0, 0.0, 0.0);
        b.scan("/scan", BagBuilder::scanMsg(6.8, room(0, 0, 0, 20)));   // 0.8 s after the last
        b.scan("/scan", BagBuilder::scanMsg(40.0, room(0, 0, 0, 20)));  // 34 s after
    }
    kfd::BagSource src(d / "s.bag");
    std::vector<SourceEntry> v;
    SourceEntry e;
    while (src.next(e)) v.push_back(e);
    std::vector<std::optional<kfd::Pose2D>> odo;
    std::vector<double> stamps;
    for (const auto& x : v)
        if (auto s = std::dynamic_pointer_cast<Scan2D>(x.observation)) {
            odo.push_back(x.odometry);
            stamps.push_back(kfd::stampOf(*s));
        }
    ASSERT_EQ(odo.size(), 5u);
    EXPECT_FALSE(odo[0].has_value());  // unknown, not the first sample 2 s later
    ASSERT_TRUE(odo[1].has_value());
    EXPECT_NEAR(odo[1]->x, 1.0, 1e-9);
    EXPECT_NEAR(stamps[2], 5.5, 1e-6);  // the bag time
    ASSERT_TRUE(odo[2].has_value());
    EXPECT_NEAR(odo[2]->x, 1.5, 1e-9);  // interpolated at it
    ASSERT_TRUE(odo[3].has_value());
    EXPECT_NEAR(odo[3]->x, 2.0, 1e-9);
    EXPECT_FALSE(odo[4].has_value());
    const kfd::SourceCounters c = src.counters();
    EXPECT_EQ(c.stamps_zero, 1u);
    EXPECT_EQ(c.scans_without_odometry, 2u);
    EXPECT_EQ(c.scans_bad_angles, 0u);
    // No odometry observation precedes a scan without odometry.
    std::size_t odometry_observations = 0;
    for (const auto& x : v)
        odometry_observations +=
            dynamic_cast<const mrpt::obs::CObservationOdometry*>(x.observation.get()) ? 1 : 0;
    EXPECT_EQ(odometry_observations, 3u);
}

TEST(BagSource, TopicChoicesAndTheirErrorsNameTheTopics) {
    TempDir d;
    {
        BagBuilder b(d / "two.bag");
        b.scan("/front", BagBuilder::scanMsg(1, {1, 2, 3}));
        b.scan("/rear", BagBuilder::scanMsg(1, {1, 2, 3}));
        b.odom("/wheel", 1, 0, 0, 0);
    }
    auto errorOf = [&](const kfd::SourceOptions& o) -> std::string {
        try {
            kfd::BagSource src(d / "two.bag", o);
        } catch (const kfd::BagError& e) {
            return e.what();
        }
        return "no error";
    };
    kfd::SourceOptions o;
    const std::string two = errorOf(o);
    EXPECT_NE(two.find(d / "two.bag"), std::string::npos) << two;
    EXPECT_NE(two.find("/front, /rear"), std::string::npos) << two;
    EXPECT_NE(two.find("--scan-topic"), std::string::npos) << two;
    o.scan_topic = "rear";  // without the slash
    kfd::BagSource rear(d / "two.bag", o);
    EXPECT_EQ(rear.choice().scan_topic, "/rear");
    EXPECT_EQ(rear.choice().odom_topic, "/wheel");  // the only Odometry topic
    o.scan_topic = "/laser";
    EXPECT_NE(errorOf(o).find("--scan-topic /laser: no such topic"), std::string::npos);
    o.scan_topic = "/wheel";
    EXPECT_NE(errorOf(o).find("holds nav_msgs/Odometry, not sensor_msgs/LaserScan"),
              std::string::npos);
    o.scan_topic = "/front";
    o.odom_topic = "/rear";
    EXPECT_NE(errorOf(o).find("--odom-topic /rear: the topic holds sensor_msgs/LaserScan"),
              std::string::npos);
    o.odom_topic = "tf";
    EXPECT_NE(errorOf(o).find("no /tf topic"), std::string::npos);
    // The listing reports the failed choice instead of throwing.
    const auto l = kfd::listSource(d / "two.bag");
    EXPECT_EQ(l.format, kfd::LogFormat::Bag);
    ASSERT_EQ(l.streams.size(), 3u);
    EXPECT_EQ(l.streams[0].name, "/front");
    EXPECT_EQ(l.streams[0].type, "sensor_msgs/LaserScan");
    EXPECT_EQ(l.streams[0].count, 1u);
    ASSERT_FALSE(l.choices.empty());
    EXPECT_NE(l.choices[0].find("cannot use as it is"), std::string::npos);
}

TEST(BagSource, Bz2AndLz4BagsReadTheSameAsAPlainOne) {
    TempDir d;
    std::vector<std::vector<Scan2D::Ptr>> all;
    for (auto c :
         {rosbag::compression::Uncompressed, rosbag::compression::BZ2, rosbag::compression::LZ4}) {
        const std::string p = d / ("c" + std::to_string(int(c)) + ".bag");
        {
            BagBuilder b(p, c);
            for (int i = 0; i < 200; ++i) {  // several chunks
                b.odom("/odom", 1 + 0.1 * i, 0.01 * i, 0, 0);
                b.scan("/scan", BagBuilder::scanMsg(1 + 0.1 * i + 0.05, room(0.01 * i, 0, 0, 361)));
            }
        }
        all.push_back(scansOf(readAll(p)));
    }
    ASSERT_EQ(all[0].size(), 200u);
    for (std::size_t k = 1; k < all.size(); ++k) {
        ASSERT_EQ(all[k].size(), all[0].size());
        for (std::size_t i = 0; i < all[0].size(); ++i) {
            EXPECT_EQ(all[k][i]->timestamp, all[0][i]->timestamp);
            for (std::size_t j = 0; j < 361; ++j)
                ASSERT_EQ(all[k][i]->getScanRange(j), all[0][i]->getScanRange(j));
        }
    }
}

// A small bag for the bad-input cases: `n` scans and odometry, bz2.
std::string smallBag(const TempDir& d, const std::string& name, int n = 300,
                     rosbag::compression::CompressionType c = rosbag::compression::BZ2) {
    const std::string p = d / name;
    BagBuilder b(p, c);
    for (int i = 0; i < n; ++i) {
        b.odom("/odom", 1 + 0.1 * i, 0.01 * i, 0, 0);
        b.scan("/scan", BagBuilder::scanMsg(1 + 0.1 * i + 0.05, room(0.01 * i, 0, 0, 361)));
    }
    return p;
}

std::string readError(const std::string& path) {
    try {
        readAll(path);
    } catch (const kfd::SourceError& e) {
        return e.what();
    }
    return "no error";
}

TEST(BagSource, TruncatedBagsAreRefusedNamingTheFile) {
    TempDir d;
    const std::string bytes = kfd::test::fileBytes(smallBag(d, "full.bag"));
    for (const std::size_t keep : {bytes.size() - 1, bytes.size() / 2, std::size_t(4200),
                                   std::size_t(4096), std::size_t(20)}) {
        const std::string p = d / ("cut" + std::to_string(keep) + ".bag");
        std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(keep));
        const std::string e = readError(p);
        EXPECT_EQ(e.rfind(p + ": ", 0), 0u) << keep << ": " << e;
        EXPECT_NE(e.find("truncated"), std::string::npos) << keep << ": " << e;
    }
}

TEST(BagSource, CorruptBagsAreRefusedNamingTheFileAndTheByte) {
    TempDir d;
    for (auto c :
         {rosbag::compression::Uncompressed, rosbag::compression::BZ2, rosbag::compression::LZ4}) {
        const std::string full = smallBag(d, "full" + std::to_string(int(c)) + ".bag", 300, c);
        const std::string bytes = kfd::test::fileBytes(full);
        // Damage 64 bytes at several places: a chunk's data, its header, an index.
        for (const double at : {0.1, 0.3, 0.5, 0.7, 0.9, 0.99}) {
            std::string bad = bytes;
            const auto pos = static_cast<std::size_t>(at * static_cast<double>(bad.size()));
            for (std::size_t i = pos; i < std::min(bad.size(), pos + 64); ++i) bad[i] ^= 0x5a;
            const std::string p = d / "bad.bag";
            std::ofstream(p, std::ios::binary | std::ios::trunc) << bad;
            try {
                readAll(p);  // damage inside a range value cannot be told (no checksums)
            } catch (const kfd::BagError& e) {
                const std::string w = e.what();
                EXPECT_EQ(w.rfind(p + ": ", 0), 0u) << w;
            }
        }
    }
    // A bag whose index entry points outside its chunk (what made rosbag_storage read out of
    // bounds) is refused by the structure check before rosbag_storage sees it.
    const std::string bytes =
        kfd::test::fileBytes(smallBag(d, "plain.bag", 30, rosbag::compression::Uncompressed));
    const auto idx = bytes.find("op=\x04");
    ASSERT_NE(idx, std::string::npos);
    std::string bad = bytes;
    // The bytes after the first index record's op: its fields and its entries' offsets.
    for (std::size_t i = idx; i < std::min(bad.size(), idx + 200); ++i) bad[i] ^= 0xff;
    const std::string p = d / "badindex.bag";
    std::ofstream(p, std::ios::binary) << bad;
    EXPECT_NE(readError(p).find(p + ": byte "), std::string::npos) << readError(p);
}

TEST(BagSource, NotABagOrAnOlderFormatIsRefused) {
    TempDir d;
    std::ofstream(d / "text.bag") << "hello\n";
    EXPECT_NE(readError(d / "text.bag").find("no '#ROSBAG V2.0' line"), std::string::npos);
    std::ofstream(d / "old.bag") << "#ROSBAG V1.2\nxxxx";
    EXPECT_THROW(kfd::detectFormat(d / "old.bag"), kfd::SourceError);
    try {
        kfd::openSource(d / "text.bag");
        ADD_FAILURE() << "a .bag without the bag line was opened";
    } catch (const kfd::SourceError& e) {
        EXPECT_NE(std::string(e.what()).find("not a ROS bag"), std::string::npos) << e.what();
    }
    { BagBuilder b(d / "empty.bag"); }
    EXPECT_NE(readError(d / "empty.bag").find("no sensor_msgs/LaserScan topic"), std::string::npos)
        << readError(d / "empty.bag");
}

// --- corrupt lengths inside messages (issue 21) --------------------------------------------

// Peak resident memory of this test process so far, in MiB.
long peakMiB() {
    struct rusage u {};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss / 1024;
}

// A bag of `n` scans with odometry on /odom and on /tf, a /tf_static mount; message k of kind
// `which` ("scan", "odom", "tf", "tf_static") is written as `bad` instead.
template <class T>
std::string bagWith(const TempDir& d, const std::string& name,
                    rosbag::compression::CompressionType c, const std::string& which, int k,
                    const kfd::test::Serialized<T>& bad, int n = 30) {
    const std::string p = d / name;
    BagBuilder b(p, c);
    auto put = [&](const std::string& kind, int i, auto write) {
        if (kind == which && i == k)
            b.raw(kind == "scan"   ? "/scan"
                  : kind == "odom" ? "/odom"
                                   : "/" + kind,
                  1 + 0.1 * i + (kind == "scan" ? 0.05 : 0.0), bad);
        else
            write();
    };
    put("tf_static", 0, [&] { b.tf("/tf_static", 1.0, "base_link", "laser", 0.1, 0, 0); });
    for (int i = 0; i < n; ++i) {
        const double t = 1 + 0.1 * i;
        put("odom", i, [&] { b.odom("/odom", t, 0.01 * i, 0, 0); });
        put("tf", i, [&] { b.tf("/tf", t, "odom", "base_link", 0.01 * i, 0, 0); });
        put("scan", i,
            [&] { b.scan("/scan", BagBuilder::scanMsg(t + 0.05, room(0.01 * i, 0, 0, 361))); });
    }
    return p;
}

std::string readError(const std::string& path, const kfd::SourceOptions& o) {
    try {
        readAll(path, o);
    } catch (const kfd::SourceError& e) {
        return e.what();
    }
    return "no error";
}

// roscpp resizes a string or array to the length it reads before it finds the bytes missing: a
// LaserScan whose ranges length read 0x40000000 took 8.4 GB. Each length is now checked
// against the bytes of its message first (bag_message_check.cpp), in bags of every compression:
// the error names the file, the message, the type, the field and both sizes.
TEST(BagSource, CorruptLengthsInsideMessagesAreRefusedNotAllocated) {
    using kfd::test::serialized;
    using kfd::test::withU32;
    TempDir d;
    const auto scan = BagBuilder::scanMsg(1.55, room(0, 0, 0, 361));
    const auto good = serialized(scan);
    const std::size_t size = good.bytes.size();
    const std::string fits = " does not fit in the message's " + std::to_string(size) + " bytes";
    nav_msgs::Odometry odom;
    odom.header.frame_id = "odom";
    odom.child_frame_id = "base_link";
    odom.header.stamp = ros::Time(1.5);
    tf2_msgs::TFMessage tf;
    tf.transforms.resize(1);
    tf.transforms[0].header.frame_id = "odom";
    tf.transforms[0].child_frame_id = "base_link";
    tf.transforms[0].header.stamp = ros::Time(1.5);
    kfd::SourceOptions via_tf;
    via_tf.odom_topic = "tf";
    for (auto c :
         {rosbag::compression::Uncompressed, rosbag::compression::BZ2, rosbag::compression::LZ4}) {
        SCOPED_TRACE(int(c));
        const std::string z = std::to_string(int(c));
        struct Case {
            std::string path, message;
            kfd::SourceOptions options;
        };
        const std::vector<Case> cases{
            // A later scan: next() names the message by its number.
            {bagWith(d, "ranges" + z + ".bag", c, "scan", 5,
                     withU32(good, kfd::test::rangesLengthAt(scan), 0x40000000u)),
             "(/scan at t = 1.550000 s): corrupt sensor_msgs/LaserScan: ranges: array length "
             "1073741824 (4294967296 bytes)" +
                 fits + " (" + std::to_string(size - kfd::test::rangesLengthAt(scan) - 4) +
                 " left)",
             {}},
            // The first scan, read when the bag is opened (its frame names the mount).
            {bagWith(d, "first" + z + ".bag", c, "scan", 0,
                     withU32(good, kfd::test::rangesLengthAt(scan), 0xffffffffu)),
             ": the message on /scan at t = 1.050000 s: corrupt sensor_msgs/LaserScan: ranges: "
             "array length 4294967295 (17179869180 bytes)" +
                 fits,
             {}},
            {bagWith(d, "intensities" + z + ".bag", c, "scan", 7,
                     withU32(good, kfd::test::intensitiesLengthAt(scan), 0x40000000u)),
             "corrupt sensor_msgs/LaserScan: intensities: array length 1073741824",
             {}},
            {bagWith(d, "frame" + z + ".bag", c, "scan", 3,
                     withU32(good, kfd::test::frameIdLengthAt(), 0xfffffff0u)),
             "corrupt sensor_msgs/LaserScan: header.frame_id: string length 4294967280" + fits,
             {}},
            // A message cut short: 361 ranges announced, 100 there.
            {bagWith(d, "short" + z + ".bag", c, "scan", 4,
                     [&] {
                         auto s = good;
                         s.bytes.resize(kfd::test::rangesLengthAt(scan) + 4 + 400);
                         return s;
                     }()),
             "ranges: array length 361 (1444 bytes) does not fit in the message's " +
                 std::to_string(kfd::test::rangesLengthAt(scan) + 4 + 400) + " bytes (400 left)",
             {}},
            {bagWith(d, "odom" + z + ".bag", c, "odom", 6,
                     withU32(serialized(odom), 12 + 4 + 4, 0x40000000u)),
             "(/odom at t = 1.600000 s): corrupt nav_msgs/Odometry: child_frame_id: string "
             "length 1073741824",
             {}},
            {bagWith(d, "tf" + z + ".bag", c, "tf", 6, withU32(serialized(tf), 0, 0x40000000u)),
             "(/tf at t = 1.600000 s): corrupt tf2_msgs/TFMessage: transforms: array length "
             "1073741824 (at least 81604378624 bytes)",
             via_tf},
            {bagWith(d, "tfchild" + z + ".bag", c, "tf", 6,
                     withU32(serialized(tf), 4 + 12 + 4 + 4, 0x40000000u)),
             "corrupt tf2_msgs/TFMessage: transforms[0].child_frame_id: string length "
             "1073741824",
             via_tf},
            {bagWith(d, "static" + z + ".bag", c, "tf_static", 0,
                     withU32(serialized(tf), 0, 0xffffffffu)),
             ": the message on /tf_static at t = 1.000000 s: corrupt tf2_msgs/TFMessage: "
             "transforms: array length 4294967295",
             {}},
        };
        for (const auto& k : cases) {
            const std::string e = readError(k.path, k.options);
            EXPECT_EQ(e.rfind(k.path + ": ", 0), 0u) << e;
            EXPECT_NE(e.find(k.message), std::string::npos) << e;
        }
    }
    EXPECT_LT(peakMiB(), 512);
}

// What the check allows: bytes after a message's last field (roscpp ignores them), empty
// arrays and strings, a LaserScan without intensities.
TEST(BagSource, TheMessageCheckRefusesNoWellFormedMessage) {
    TempDir d;
    auto scan = BagBuilder::scanMsg(1.55, room(0, 0, 0, 361), "");
    auto longer = kfd::test::serialized(scan);
    longer.bytes.insert(longer.bytes.end(), {1, 2, 3});
    const auto p = bagWith(d, "ok.bag", rosbag::compression::LZ4, "scan", 5, longer);
    const auto scans = scansOf(readAll(p));
    ASSERT_EQ(scans.size(), 30u);
    EXPECT_EQ(scans[5]->getScanSize(), 361u);
    EXPECT_EQ(scans[5]->getScanRange(180), scan.ranges[180]);
}

// A chunk's announced size is no longer allocated before its data decompresses: an 18 kB bag
// whose chunk claims 2 GiB took 2.1 GB. The output grows with what the data holds; a chunk
// larger than LZ4's 4 MiB blocks (several blocks) and bz2's still read.
TEST(BagSource, AChunkSizeFieldIsCheckedNotAllocated) {
    TempDir d;
    for (auto c : {rosbag::compression::BZ2, rosbag::compression::LZ4}) {
        SCOPED_TRACE(int(c));
        std::string bytes =
            kfd::test::fileBytes(smallBag(d, "c" + std::to_string(int(c)) + ".bag", 30, c));
        const auto at = bytes.find("size=");
        ASSERT_NE(at, std::string::npos);
        for (const std::uint32_t size : {0x7fffffffu, 1000u}) {
            std::string bad = bytes;
            for (int i = 0; i < 4; ++i) bad[at + 5 + i] = static_cast<char>(size >> (8 * i));
            const std::string p = d / "bad.bag";
            std::ofstream(p, std::ios::binary | std::ios::trunc) << bad;
            const std::string e = readError(p);
            EXPECT_NE(e.find("a chunk decompresses to another size than announced"),
                      std::string::npos)
                << e;
        }
        const std::string big = d / ("big" + std::to_string(int(c)) + ".bag");
        {
            BagBuilder b(big, c);
            b.scan("/scan", BagBuilder::scanMsg(1.0, room(0, 0, 0, 1500000)));  // 6 MB
            b.scan("/scan", BagBuilder::scanMsg(1.1, room(0, 0, 0, 361)));
        }
        EXPECT_EQ(readAll(big).size(), 2u);
    }
    EXPECT_LT(peakMiB(), 512);
}

// --- reading chunks once -------------------------------------------------------------------

// Issue 23: a bag of several high-rate topics read through decompressed each chunk 2.4 times
// (kfd's structure check once, rosbag_storage again each time the messages held for the
// odometry after a scan were copied from a chunk it had left). Now each chunk is loaded once,
// also when the chunks' times overlap (read in time order, back and forth between them).
TEST(BagSource, EachChunkIsDecompressedOnceBesideSeveralHighRateTopics) {
    TempDir d;
    for (auto c : {rosbag::compression::BZ2, rosbag::compression::LZ4}) {
        std::vector<std::vector<SourceEntry>> read;
        for (const bool by_topic : {false, true}) {
            SCOPED_TRACE(std::to_string(int(c)) + (by_topic ? " by topic" : " in time order"));
            const std::string p =
                d / ("fast" + std::to_string(int(c)) + std::to_string(by_topic) + ".bag");
            kfd::test::writeFastScannerBag(p, c, by_topic, 6.0);
            kfd::BagSource src(p);
            std::vector<SourceEntry> v;
            SourceEntry e;
            while (src.next(e)) v.push_back(e);
            EXPECT_GE(src.chunks(), 4u);
            EXPECT_EQ(src.chunksLoaded(), src.chunks());
            EXPECT_EQ(src.compression(), c == rosbag::compression::BZ2 ? "bz2" : "lz4");
            read.push_back(std::move(v));
        }
        // The same messages written in another order read the same (rosbag::View's order).
        ASSERT_EQ(read[0].size(), read[1].size());
        const auto a = scansOf(read[0]), b = scansOf(read[1]);
        ASSERT_GT(a.size(), 150u);  // 6 s at 35 Hz
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t i = 0; i < read[0].size(); ++i) {
            ASSERT_EQ(read[0][i].kind, read[1][i].kind) << i;
            ASSERT_EQ(read[0][i].odometry.has_value(), read[1][i].odometry.has_value()) << i;
            if (read[0][i].odometry) {
                EXPECT_EQ(read[0][i].odometry->x, read[1][i].odometry->x);
            }
        }
        for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i]->timestamp, b[i]->timestamp);
    }
}

// The chunks' contents are checked when the source first reads them (each chunk decompressed
// once): an index entry whose offset names no message record of its chunk, its lengths all
// fitting, is still refused, naming the chunk's byte (the listing, which reads the first chunk
// for the first messages, says so among its choices).
TEST(BagSource, AnIndexEntryThatPointsBetweenMessagesIsRefusedWhenItsChunkIsRead) {
    TempDir d;
    std::string bytes =
        kfd::test::fileBytes(smallBag(d, "ok.bag", 30, rosbag::compression::Uncompressed));
    // The first index data record: header fields conn, count, op, ver (rosbag writes them in
    // this order), then its data length and 12-byte entries (time, offset).
    const auto op = bytes.find(std::string("op=\x04", 4));
    ASSERT_NE(op, std::string::npos);
    const std::size_t header = op - 4 - (4 + 10) - (4 + 9);
    auto u32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        for (int i = 0; i < 4; ++i) v |= std::uint32_t(std::uint8_t(bytes[at + i])) << (8 * i);
        return v;
    };
    ASSERT_EQ(u32(header - 4), 47u);  // 4 fields: 4 + 9, 4 + 10, 4 + 4, 4 + 8 bytes
    const std::size_t entry = header + 47 + 4;
    bytes[entry + 8] = static_cast<char>(bytes[entry + 8] + 1);  // offset + 1
    const std::string p = d / "between.bag";
    std::ofstream(p, std::ios::binary) << bytes;
    const std::string e = readError(p);
    EXPECT_EQ(e.rfind(p + ": byte ", 0), 0u) << e;
    EXPECT_NE(e.find("an index entry points to no message of its chunk"), std::string::npos) << e;
    // The listing reads the index only, then the chunk of the first messages for its choices:
    // it lists the topics and says why the bag cannot be used as it is.
    const auto l = kfd::listBag(p);
    std::string choices;
    for (const auto& c : l.choices) choices += c + "\n";
    EXPECT_NE(choices.find("an index entry points to no message of its chunk"), std::string::npos)
        << choices;
}

// --- the filtered bag ---------------------------------------------------------------------

struct Msg {
    std::string topic;
    double time;
    std::string bytes;
};

std::vector<Msg> messagesOf(const std::string& path) {
    rosbag::Bag bag(path);
    rosbag::View v(bag);
    std::vector<Msg> out;
    for (const rosbag::MessageInstance& m : v) {
        std::vector<std::uint8_t> buf(m.size());
        ros::serialization::OStream s(buf.data(), static_cast<std::uint32_t>(buf.size()));
        m.write(s);
        out.push_back({m.getTopic(), m.getTime().toSec(), std::string(buf.begin(), buf.end())});
    }
    return out;
}

std::vector<sensor_msgs::LaserScan> laserScans(const std::string& path) {
    rosbag::Bag bag(path);
    rosbag::View v(bag, rosbag::TopicQuery("/scan"));
    std::vector<sensor_msgs::LaserScan> out;
    for (const rosbag::MessageInstance& m : v)
        out.push_back(*m.instantiate<sensor_msgs::LaserScan>());
    return out;
}

// Issue 37: a MultiEchoLaserScan topic (Cartographer's backpack logs) is not read; --list and
// the summary say so, a bag output copies it byte for byte; a bag holding only multi-echo
// scans is refused with what it holds.
TEST(BagOutput, MultiEchoScansAreSaidToBeCopiedUnfiltered) {
    TempDir d;
    kfd::test::FastScanner scanner;
    scanner.beams = 181;
    kfd::test::writeFastScannerBag(d / "in.bag", rosbag::compression::LZ4, false, 2.0, scanner);
    const auto l = kfd::listSource(d / "in.bag");
    bool said = false;
    for (const auto& c : l.choices)
        said = said ||
               c.rfind("not read: /echoes (sensor_msgs/MultiEchoLaserScan, 70 messages)", 0) == 0;
    EXPECT_TRUE(said);
    kfd::RawlogFilterOptions o;
    o.input = d / "in.bag";
    o.output = d / "out.bag";
    o.pipeline = kfd::kfdDefaults();
    const auto sum = kfd::RawlogFilter().run(o);
    ASSERT_EQ(sum.unread_scans.size(), 1u);
    EXPECT_EQ(sum.unread_scans[0], "/echoes (sensor_msgs/MultiEchoLaserScan, 70 messages)");
    std::vector<std::string> in, out;
    for (const auto& m : messagesOf(d / "in.bag"))
        if (m.topic == "/echoes") in.push_back(m.bytes);
    for (const auto& m : messagesOf(d / "out.bag"))
        if (m.topic == "/echoes") out.push_back(m.bytes);
    EXPECT_EQ(in.size(), 70u);
    EXPECT_EQ(in, out);

    {
        rosbag::Bag only(d / "only.bag", rosbag::bagmode::Write);
        sensor_msgs::MultiEchoLaserScan m;
        m.header.stamp = ros::Time(1.0);
        only.write("/echoes", ros::Time(1.0), m);
    }
    try {
        kfd::BagSource src(d / "only.bag");
        ADD_FAILURE() << "opened";
    } catch (const kfd::BagError& e) {
        EXPECT_NE(std::string(e.what()).find("no sensor_msgs/LaserScan topic"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("not /echoes (sensor_msgs/MultiEchoLaserScan"),
                  std::string::npos)
            << e.what();
    }
}

// Issue 37: with beam_count, a bag output's scans carry the fixed count, with the increment,
// angle_max and ranges that go with it (rosbag reads them back).
TEST(BagOutput, ABeamCountStageWritesScansOfTheFixedCount) {
    TempDir d;
    {
        BagBuilder b(d / "in.bag");
        for (int i = 0; i < 40; ++i) {
            const double t = 1 + 0.1 * i;
            b.odom("/odom", t, 0.05 * i, 0, 0);
            b.scan("/scan",
                   BagBuilder::scanMsg(t + 0.05, room(0.05 * i, 0, 0, 361 - (i % 3)), "laser"));
        }
    }
    kfd::RawlogFilterOptions o;
    o.input = d / "in.bag";
    o.output = d / "out.bag";
    o.pipeline = kfd::loadYamlText(
        "pipeline: [beam_count, odometry_check, distance, track, view_keyframe, "
        "evidence_denoise]\nbeam_count:\n  beam_count: 200\n");
    const auto sum = kfd::RawlogFilter().run(o);
    EXPECT_EQ(sum.geometry_resets, 0u);
    const auto scans = laserScans(d / "out.bag");
    ASSERT_EQ(scans.size(), sum.scans_kept);
    ASSERT_GT(scans.size(), 0u);
    for (const auto& m : scans) {
        EXPECT_EQ(m.ranges.size(), 200u);
        EXPECT_NEAR(m.angle_min, -1.5f, 1e-6);
        EXPECT_NEAR(m.angle_max, 1.5f, 1e-4);
        EXPECT_NEAR(m.angle_increment, 3.0f / 199.0f, 1e-6);
        std::size_t finite = 0;
        for (float r : m.ranges) finite += std::isfinite(r) ? 1 : 0;
        EXPECT_GT(finite, 150u);
    }
}

TEST(BagOutput, DroppedScansLeaveEveryOtherMessageIsCopiedRemovedPointsAreMarked) {
    TempDir d;
    {
        BagBuilder b(d / "in.bag", rosbag::compression::BZ2);
        b.tf("/tf_static", 1.0, "base_link", "laser", 0.1, 0, 0);
        for (int i = 0; i < 120; ++i) {
            const double t = 1 + 0.1 * i, x = i < 60 ? 0.0 : 0.02 * (i - 60);  // still, then moving
            b.odom("/odom", t, x, 0, 0);
            b.tf("/tf", t, "odom", "base_link", x, 0, 0);
            auto r = room(x + 0.1, 0, 0, 361);
            if (i % 10 == 5) r[100] = 0.5f;  // an isolated noise point
            b.scan("/scan", BagBuilder::scanMsg(t + 0.05, r, "laser"));
        }
    }
    kfd::RawlogFilterOptions o;
    o.input = d / "in.bag";
    o.output = d / "out.bag";
    o.pipeline = kfd::kfdDefaults();
    const auto sum = kfd::RawlogFilter().run(o);
    EXPECT_EQ(sum.input_format, kfd::LogFormat::Bag);
    EXPECT_EQ(sum.output_format, kfd::LogFormat::Bag);
    ASSERT_EQ(sum.scans_in, 120u);
    ASSERT_GT(sum.scans_dropped, 0u);
    ASSERT_GT(sum.scans_kept, 0u);

    const auto in = messagesOf(d / "in.bag");
    const auto out = messagesOf(d / "out.bag");
    // Every non-scan message copied byte for byte, in time order.
    std::multimap<std::pair<double, std::string>, std::string> others_in, others_out;
    for (const auto& m : in)
        if (m.topic != "/scan") others_in.emplace(std::make_pair(m.time, m.topic), m.bytes);
    for (const auto& m : out)
        if (m.topic != "/scan") others_out.emplace(std::make_pair(m.time, m.topic), m.bytes);
    EXPECT_EQ(others_in, others_out);
    for (std::size_t i = 1; i < out.size(); ++i) EXPECT_LE(out[i - 1].time, out[i].time);
    EXPECT_EQ(out.size(), in.size() - sum.scans_dropped);
    EXPECT_EQ(sum.objects_out, out.size());

    // Kept scans: every field kept; the removed beams (valid before) are NaN, nothing else moved.
    const auto scans_in = laserScans(d / "in.bag");
    const auto scans_out = laserScans(d / "out.bag");
    ASSERT_EQ(scans_out.size(), sum.scans_kept);
    std::size_t marked = 0, j = 0;
    for (const auto& s : scans_out) {
        while (j < scans_in.size() && scans_in[j].header.stamp != s.header.stamp) ++j;
        ASSERT_LT(j, scans_in.size()) << "a kept scan that was not in the input";
        const auto& r = scans_in[j];
        EXPECT_EQ(s.header.frame_id, r.header.frame_id);
        EXPECT_EQ(s.header.seq, r.header.seq);
        EXPECT_EQ(s.angle_min, r.angle_min);
        EXPECT_EQ(s.range_max, r.range_max);
        ASSERT_EQ(s.ranges.size(), r.ranges.size());
        for (std::size_t k = 0; k < s.ranges.size(); ++k) {
            if (std::isnan(s.ranges[k]) && !std::isnan(r.ranges[k])) {
                ++marked;
            } else {
                EXPECT_EQ(s.ranges[k], r.ranges[k]);
            }
        }
    }
    EXPECT_EQ(marked, sum.points_marked);
    EXPECT_EQ(sum.points_marked, sum.stageTotal("points_removed_range") + sum.points_removed_noise);
    EXPECT_GT(sum.points_removed_noise, 0u);  // the planted noise points of kept scans

    // --removed-as inf; a rawlog output from a bag holds the scans and odometry.
    o.output = d / "inf.bag";
    o.bag.removed = kfd::RemovedMark::PlusInf;
    o.bag.compression = kfd::BagWriterOptions::Compression::None;
    const auto inf = kfd::RawlogFilter().run(o);
    std::size_t infs = 0;
    for (const auto& s : laserScans(d / "inf.bag"))
        for (float r : s.ranges) infs += std::isinf(r) && r > 0 ? 1 : 0;
    EXPECT_EQ(infs, inf.points_marked);
    o.output = d / "out.rawlog";
    const auto rl = kfd::RawlogFilter().run(o);
    EXPECT_EQ(rl.output_format, kfd::LogFormat::Rawlog);
    EXPECT_EQ(rl.scans_kept, sum.scans_kept);
    kfd::RawlogSource back(d / "out.rawlog");
    SourceEntry e;
    std::size_t scans = 0, odometry = 0;
    while (back.next(e)) {
        scans += std::dynamic_pointer_cast<Scan2D>(e.observation) ? 1 : 0;
        odometry +=
            std::dynamic_pointer_cast<mrpt::obs::CObservationOdometry>(e.observation) ? 1 : 0;
    }
    EXPECT_EQ(scans, sum.scans_kept);
    EXPECT_EQ(odometry, 120u);

    // A bag output needs a bag input.
    kfd::RawlogFilterOptions r;
    r.input = d / "out.rawlog";
    r.output = d / "x.bag";
    EXPECT_THROW(kfd::RawlogFilter().run(r), kfd::RawlogError);
    EXPECT_FALSE(fs::exists(d / "x.bag"));
}

// next_scan (issue 25): each kept scan waits for the next scan, and every message after it
// waits with it; the output holds the same messages in the same order as without the key.
TEST(BagOutput, WithNextScanTheSameMessagesComeOutInTheSameOrder) {
    TempDir d;
    {
        BagBuilder b(d / "in.bag", rosbag::compression::BZ2);
        b.tf("/tf_static", 1.0, "base_link", "laser", 0.1, 0, 0);
        for (int i = 0; i < 80; ++i) {
            const double t = 1 + 0.1 * i, x = i < 40 ? 0.0 : 0.02 * (i - 40);
            b.odom("/odom", t, x, 0, 0);
            b.tf("/tf", t, "odom", "base_link", x, 0, 0);
            auto r = room(x + 0.1, 0, 0, 361);
            if (i % 10 == 5) r[100] = 0.5f;
            b.scan("/scan", BagBuilder::scanMsg(t + 0.05, r, "laser"));
        }
    }
    kfd::RawlogFilterOptions o;
    o.input = d / "in.bag";
    o.output = d / "on.bag";
    o.pipeline = kfd::kfdDefaults();
    auto off = o;
    off.output = d / "off.bag";
    o.pipeline.get<kfd::EvidenceDenoiseStage>().next_scan = true;
    const auto a = kfd::RawlogFilter().run(o);
    const auto b = kfd::RawlogFilter().run(off);
    EXPECT_EQ(a.scans_kept, b.scans_kept);
    EXPECT_EQ(a.objects_out, b.objects_out);
    EXPECT_EQ(a.points_marked, a.stageTotal("points_removed_range") + a.points_removed_noise);
    const auto ma = messagesOf(d / "on.bag"), mb = messagesOf(d / "off.bag");
    ASSERT_EQ(ma.size(), mb.size());
    for (std::size_t i = 0; i < ma.size(); ++i) {
        EXPECT_EQ(ma[i].topic, mb[i].topic) << i;
        EXPECT_EQ(ma[i].time, mb[i].time) << i;
        if (ma[i].topic != "/scan") {
            EXPECT_EQ(ma[i].bytes, mb[i].bytes) << i;
        }
    }
}

// Issue 23: a filtered bag was written lz4 whatever its input (1.36 MB from a 1.38 MB bz2 bag
// whose scans were 76 % dropped; bz2: 0.77 MB). Its chunks now take the input's compression,
// unless BagWriterOptions (kfd-filter --bag-compression) names one.
TEST(BagOutput, IsCompressedLikeItsInputUnlessToldOtherwise) {
    TempDir d;
    const auto& kinds = kfd::test::bagCompressions();
    for (const auto& [c, name] : kinds) {
        SCOPED_TRACE(name);
        kfd::RawlogFilterOptions o;
        o.input = smallBag(d, "in-" + name + ".bag", 200, c);
        o.pipeline = kfd::kfdDefaults();
        o.output = d / ("out-" + name + ".bag");
        kfd::RawlogFilter().run(o);
        EXPECT_EQ(kfd::test::chunkCompressions(o.output), std::set<std::string>{name});
        EXPECT_EQ(kfd::BagSource(o.output).compression(), name);
        for (const auto& [told, told_name] : kinds) {
            o.output = d / ("out-" + name + "-" + told_name + ".bag");
            o.bag.compression = kfd::parseBagCompression(told_name);
            kfd::RawlogFilter().run(o);
            EXPECT_EQ(kfd::test::chunkCompressions(o.output), std::set<std::string>{told_name});
        }
    }
    EXPECT_EQ(kfd::parseBagCompression("input"), kfd::BagWriterOptions::Compression::AsInput);
    EXPECT_THROW(kfd::parseBagCompression("zip"), kfd::Error);
}

// --- real bags against their rawlogs --------------------------------------------------------

const std::string kData = KFD_DATASETS_DIR;

struct Decided {
    std::vector<Scan2D::Ptr> scans;
    std::vector<std::optional<kfd::Pose2D>> odometry;
    std::vector<bool> keep;
    std::size_t jumps = 0;  // scans the odometry check (kfd's defaults) found jumping
};

// kfd's defaults without the odometry check: its jump test compares shares of sampled beams
// against a margin, and the bag's odometry (doubles) and the rawlog's (CARMEN text, 6 decimals)
// put one or two scans of a log on either side of it (counted below, not compared one by one).
Decided decide(kfd::Source& src) {
    Decided d;
    kfd::Pipeline::Params p = kfd::kfdDefaults();
    std::vector<std::string> stages;
    for (const auto& s : p.stages)
        if (s != "odometry_check") stages.push_back(s);
    EXPECT_EQ(stages.size() + 1, p.stages.size());
    p.stages = stages;
    kfd::StreamFilter f(p), checked(kfd::kfdDefaults());
    SourceEntry e;
    while (src.next(e))
        e.forEachScan([&](const Scan2D::Ptr& s) {
            d.scans.push_back(std::make_shared<Scan2D>(*s));  // before the filter cleans it
            d.odometry.push_back(e.odometry);
            auto copy = *s;
            const auto r = checked.process(copy, e.odometry);
            d.jumps += checked.outputs().cell(r.report, "odometry_check") == "jump";
            d.keep.push_back(f.process(*s, e.odometry).keep);
        });
    return d;
}

class FreiburgBag : public ::testing::TestWithParam<const char*> {};

TEST_P(FreiburgBag, GivesTheScansStampsOdometryAndKeyframeDecisionsOfItsRawlog) {
    const std::string name = GetParam();
    const std::string bag = kData + "/" + name + "/" + name + ".orig.bag";
    const std::string rawlog = kData + "/" + name + "/" + name + ".rawlog";
    if (!fs::exists(bag) || !fs::exists(rawlog)) GTEST_SKIP() << "dataset missing: " << bag;
    kfd::BagSource b(bag);
    kfd::RawlogSource r(rawlog);
    const Decided x = decide(b), y = decide(r);
    ASSERT_EQ(x.scans.size(), y.scans.size());
    std::size_t decisions_differ = 0;
    for (std::size_t i = 0; i < x.scans.size(); ++i) {
        const Scan2D &s = *x.scans[i], &t = *y.scans[i];
        ASSERT_EQ(s.getScanSize(), t.getScanSize()) << i;
        // The rawlog's stamps went through CARMEN text (6 decimals) and MRPT's workaround.
        ASSERT_NEAR(kfd::stampOf(s), kfd::stampOf(t), 2.5e-6) << i;
        for (std::size_t k = 0; k < s.getScanSize(); ++k) {
            ASSERT_EQ(s.getScanRangeValidity(k), t.getScanRangeValidity(k)) << i << " " << k;
            if (t.getScanRangeValidity(k)) {
                ASSERT_EQ(s.getScanRange(k), t.getScanRange(k));
            }
        }
        ASSERT_NEAR(s.aperture, t.aperture, 1e-6);
        ASSERT_NEAR(s.sensorPose.x(), t.sensorPose.x(), 1e-5);
        ASSERT_NEAR(s.sensorPose.yaw(), t.sensorPose.yaw(), 1e-5);
        ASSERT_EQ(x.odometry[i].has_value(), y.odometry[i].has_value());
        if (x.odometry[i]) {  // the rawlog's odometry is the CARMEN text's (6 decimals)
            ASSERT_NEAR(x.odometry[i]->x, y.odometry[i]->x, 2e-6) << i;
            ASSERT_NEAR(x.odometry[i]->y, y.odometry[i]->y, 2e-6) << i;
            ASSERT_NEAR(x.odometry[i]->phi, y.odometry[i]->phi, 2e-6) << i;
        }
        decisions_differ += x.keep[i] != y.keep[i] ? 1 : 0;
    }
    EXPECT_EQ(decisions_differ, 0u);
    EXPECT_NEAR(static_cast<double>(x.jumps), static_cast<double>(y.jumps), 2.0);
}

INSTANTIATE_TEST_SUITE_P(Datasets, FreiburgBag, ::testing::Values("aces", "intel", "fr079"));

TEST(CcnyBag, RunsLaserOnlyEndToEndIntoAFilteredBag) {
    const std::string bag = kData + "/ccny-urg/demo.bag";
    if (!fs::exists(bag)) GTEST_SKIP() << "dataset missing: " << bag;
    TempDir d;
    kfd::RawlogFilterOptions o;
    o.input = bag;
    o.output = d / "out.bag";
    o.stats_csv = d / "stats.csv";
    o.pipeline = kfd::kfdDefaults();
    const auto sum = kfd::RawlogFilter().run(o);
    EXPECT_EQ(sum.scans_in, 360u);
    EXPECT_EQ(sum.sensor.beams, 681u);
    EXPECT_FALSE(sum.sensor.odometry);
    EXPECT_NEAR(sum.sensor.rate_hz, 10.0, 0.2);
    EXPECT_GT(sum.droppedPercent(), 20.0);  // a hand-held sensor often at rest
    EXPECT_LT(sum.droppedPercent(), 90.0);
    EXPECT_EQ(laserScans(d / "out.bag").size(), sum.scans_kept);
    const auto l = kfd::listSource(bag);
    ASSERT_EQ(l.streams.size(), 1u);
    EXPECT_EQ(l.streams[0].count, 360u);
}

}  // namespace
