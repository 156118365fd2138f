// ROS 2 logs: rosbag2 (.db3, a folder with metadata.yaml) and MCAP, read (BagSource) and written
// (Ros2Writer, kfd-filter -o X.db3 / X.mcap). A real ROS 1 bag converted to both gives the same
// keyframes and removals; the real rosbag2 recordings of an RPLIDAR read as they are; bad files
// are refused with a clear message.
#include <gtest/gtest.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/LaserScan.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "kfd/io/bag_source.h"
#include "kfd/io/open_source.h"
#include "kfd/io/rawlog_filter.h"
#include "kfd/io/ros2_writer.h"
#include "kfd/io/source_listing.h"
#include "kfd/mrpt/config.h"
#include "test_bags.h"
#include "test_files.h"

namespace fs = std::filesystem;
using mrpt::obs::CObservation2DRangeScan;

namespace {

const std::string kDatasets = KFD_DATASETS_DIR;
const std::string kFr079Bag = kDatasets + "/fr079/fr079.orig.bag";
const std::string kMumble = kDatasets + "/mumble-rplidar-ros2";

// Every message of a bag (ROS 1, rosbag2 or MCAP) written to `out` (.db3 or .mcap) as it came:
// the converter the tests make their ROS 2 copies of a ROS 1 bag with.
std::size_t convert(const std::string& in, const std::string& out) {
    kfd::LogFormat format;
    EXPECT_TRUE(kfd::ros2OutputFormat(out, format));
    kfd::BagSource source(in);
    kfd::Ros2Writer writer(out, format);
    kfd::SourceEntry e;
    while (source.next(e))
        if (e.native) writer.copy(*e.native);
    writer.close();
    return writer.messagesWritten();
}

void write(const std::string& p, const std::string& b) { std::ofstream(p, std::ios::binary) << b; }

struct ScanRow {
    double t;
    std::vector<float> ranges;
    std::vector<char> valid;
};

std::vector<ScanRow> scansOf(const std::string& path) {
    std::vector<ScanRow> rows;
    auto source = kfd::openSource(path);
    kfd::SourceEntry e;
    while (source->next(e))
        e.forEachScan([&](const CObservation2DRangeScan::Ptr& s) {
            ScanRow r;
            r.t = kfd::stampOf(*s);
            for (std::size_t i = 0; i < s->getScanSize(); ++i) {
                r.valid.push_back(s->getScanRangeValidity(i) ? 1 : 0);
                r.ranges.push_back(s->getScanRangeValidity(i) ? s->getScanRange(i) : 0.0f);
            }
            rows.push_back(std::move(r));
        });
    return rows;
}

// The per-scan stats CSV's rows without the `microseconds` column (the time each scan took).
std::vector<std::string> statsRows(const std::string& csv) {
    std::ifstream f(csv);
    std::vector<std::string> rows;
    int skip = -1;
    for (std::string line; std::getline(f, line);) {
        std::vector<std::string> cols;
        std::size_t at = 0;
        for (std::size_t c; (c = line.find(',', at)) != std::string::npos; at = c + 1)
            cols.push_back(line.substr(at, c - at));
        cols.push_back(line.substr(at));
        if (skip < 0)
            for (std::size_t i = 0; i < cols.size(); ++i)
                if (cols[i] == "microseconds") skip = static_cast<int>(i);
        std::string row;
        for (std::size_t i = 0; i < cols.size(); ++i)
            if (static_cast<int>(i) != skip) row += cols[i] + ",";
        rows.push_back(row);
    }
    return rows;
}

kfd::RawlogFilterSummary filter(
    const std::string& in, const std::string& out, const std::string& stats,
    kfd::BagWriterOptions::Compression c = kfd::BagWriterOptions::Compression::AsInput) {
    kfd::RawlogFilterOptions o;
    o.input = in;
    o.output = out;
    o.stats_csv = stats;
    o.bag.compression = c;
    o.pipeline = kfd::kfdDefaults();
    return kfd::RawlogFilter().run(o);
}

sensor_msgs::LaserScan tinyScan(double t, float r) {
    sensor_msgs::LaserScan m;
    m.header.stamp.fromSec(t);
    m.header.frame_id = "laser";
    m.angle_min = -1.5f;
    m.angle_max = 1.5f;
    m.angle_increment = 0.5f;
    m.range_min = 0.1f;
    m.range_max = 20.0f;
    m.ranges = {r, r + 1, r + 2, r + 3, std::nanf(""), r + 5, r + 6};
    m.intensities = {1, 2, 3, 4, 5, 6, 7};
    return m;
}

}  // namespace

TEST(Ros2Logs, AHandMadeBagSurvivesBothFormatsFieldForField) {
    kfd::test::TempDir d("ros2_");
    {
        rosbag::Bag bag(d / "in.bag", rosbag::bagmode::Write);
        for (int i = 0; i < 5; ++i) {
            nav_msgs::Odometry od;
            od.header.stamp.fromSec(100.0 + 0.1 * i);
            od.header.frame_id = "odom";
            od.child_frame_id = "base_link";
            od.pose.pose.position.x = 0.01 * i;
            od.pose.pose.orientation = kfd::test::yawQuaternion(0.02 * i);
            bag.write("/odom", od.header.stamp, od);
            const auto s = tinyScan(100.05 + 0.1 * i, 1.0f + i);
            bag.write("/scan", s.header.stamp, s);
            sensor_msgs::Imu imu;  // not a type kfd converts: left out of a ROS 2 copy
            imu.header.stamp = s.header.stamp;
            bag.write("/imu", s.header.stamp, imu);
        }
    }
    const auto ref = scansOf(d / "in.bag");
    ASSERT_EQ(ref.size(), 5u);
    for (const char* out : {"c.db3", "c.mcap"}) {
        SCOPED_TRACE(out);
        EXPECT_EQ(convert(d / "in.bag", d / out), 10u);  // 5 scans + 5 odometry, no Imu
        const auto got = scansOf(d / out);
        ASSERT_EQ(got.size(), ref.size());
        for (std::size_t i = 0; i < ref.size(); ++i) {
            EXPECT_NEAR(got[i].t, ref[i].t, 1e-9);
            EXPECT_EQ(got[i].ranges, ref[i].ranges);
            EXPECT_EQ(got[i].valid, ref[i].valid);
        }
        // The odometry came along: the same poses before each scan.
        kfd::BagSource a(d / "in.bag"), b(d / out);
        EXPECT_EQ(b.choice().odometry, kfd::BagChoice::Odometry::Topic);
        EXPECT_EQ(b.choice().odom_topic, "/odom");
        kfd::SourceEntry ea, eb;
        while (a.next(ea)) {
            if (ea.kind == kfd::SourceEntry::Kind::Native) continue;
            do ASSERT_TRUE(b.next(eb));
            while (eb.kind == kfd::SourceEntry::Kind::Native);
            ASSERT_EQ(ea.odometry.has_value(), eb.odometry.has_value());
            if (ea.odometry) {
                EXPECT_NEAR(ea.odometry->x, eb.odometry->x, 1e-12);
                EXPECT_NEAR(ea.odometry->phi, eb.odometry->phi, 1e-12);
            }
        }
    }
    EXPECT_EQ(kfd::detectFormat(d / "c.db3"), kfd::LogFormat::Rosbag2);
    EXPECT_EQ(kfd::detectFormat(d / "c.mcap"), kfd::LogFormat::Mcap);
}

TEST(Ros2Logs, ARosbag2FolderOfMcapOrOfSplitDb3FilesReadsLikeItsFiles) {
    kfd::test::TempDir d("ros2_");
    {
        rosbag::Bag bag(d / "in.bag", rosbag::bagmode::Write);
        for (int i = 0; i < 6; ++i) {
            const auto s = tinyScan(100.0 + 0.1 * i, 1.0f + i);
            bag.write("/scan", s.header.stamp, s);
        }
    }
    const auto ref = scansOf(d / "in.bag");
    // A folder whose metadata.yaml names one MCAP file (rosbag2's default from Iron on).
    fs::create_directories(d / "m");
    convert(d / "in.bag", d / "m/m_0.mcap");
    write(d / "m/metadata.yaml",
          "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n"
          "  relative_file_paths:\n    - m_0.mcap\n");
    EXPECT_EQ(kfd::detectFormat(d / "m"), kfd::LogFormat::Rosbag2);
    const auto m = scansOf(d / "m");
    ASSERT_EQ(m.size(), ref.size());
    for (std::size_t i = 0; i < ref.size(); ++i) EXPECT_EQ(m[i].ranges, ref[i].ranges);
    // A split sqlite3 bag: its two files read one after the other.
    fs::create_directories(d / "s");
    convert(d / "in.bag", d / "s/s_0.db3");
    convert(d / "in.bag", d / "s/s_1.db3");
    write(d / "s/metadata.yaml",
          "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n"
          "  relative_file_paths:\n    - s_0.db3\n    - s_1.db3\n");
    const auto l = kfd::listSource(d / "s");
    ASSERT_EQ(l.streams.size(), 1u);
    EXPECT_EQ(l.streams[0].count, 2 * ref.size());
}

TEST(Ros2Logs, ARealBagAsDb3AndMcapGivesTheSameKeyframesAndRemovals) {
    if (!fs::exists(kFr079Bag)) GTEST_SKIP() << "dataset missing: " << kFr079Bag;
    kfd::test::TempDir d("ros2_");
    const std::size_t copied = convert(kFr079Bag, d / "fr079.db3");
    EXPECT_EQ(convert(kFr079Bag, d / "fr079.mcap"), copied);
    const auto a = filter(kFr079Bag, d / "out.bag", d / "a.csv");
    const auto b = filter(d / "fr079.db3", d / "out.db3", d / "b.csv");
    const auto c = filter(d / "fr079.mcap", d / "out.mcap", d / "c.csv");
    EXPECT_GT(a.scans_in, 4000u);
    EXPECT_EQ(b.scans_in, a.scans_in);
    EXPECT_EQ(c.scans_in, a.scans_in);
    EXPECT_EQ(b.scans_kept, a.scans_kept);
    EXPECT_EQ(c.scans_kept, a.scans_kept);
    EXPECT_EQ(b.points_marked, a.points_marked);
    EXPECT_EQ(c.points_marked, a.points_marked);
    EXPECT_GT(a.points_marked, 0u);
    // Per-scan decisions, removals and poses, row for row (all but the time taken).
    const auto rows = statsRows(d / "a.csv");
    EXPECT_EQ(rows.size(), a.scans_in + 1);
    EXPECT_TRUE(statsRows(d / "b.csv") == rows);
    EXPECT_TRUE(statsRows(d / "c.csv") == rows);
    // The kept scans as written: the same stamps and ranges, removed points NaN in all three.
    const auto ra = scansOf(d / "out.bag"), rb = scansOf(d / "out.db3"),
               rc = scansOf(d / "out.mcap");
    ASSERT_EQ(ra.size(), a.scans_kept);
    ASSERT_EQ(rb.size(), ra.size());
    ASSERT_EQ(rc.size(), ra.size());
    for (std::size_t i = 0; i < ra.size(); ++i) {
        EXPECT_EQ(rb[i].t, ra[i].t);
        EXPECT_EQ(rc[i].t, ra[i].t);
        EXPECT_EQ(rb[i].valid, ra[i].valid);
        EXPECT_EQ(rc[i].valid, ra[i].valid);
        EXPECT_EQ(rb[i].ranges, ra[i].ranges);
        EXPECT_EQ(rc[i].ranges, ra[i].ranges);
    }
}

TEST(Ros2Logs, TheRealRplidarRecordingsReadAsTheyAre) {
    const std::string bag = kMumble + "/hallway_room_loop";
    if (!fs::exists(bag)) GTEST_SKIP() << "dataset missing: " << bag;
    const auto l = kfd::listSource(bag);
    EXPECT_EQ(l.format, kfd::LogFormat::Rosbag2);
    ASSERT_EQ(l.streams.size(), 2u);
    kfd::test::TempDir d("ros2_");
    const auto s = filter(bag, d / "out.mcap", d / "s.csv");
    EXPECT_EQ(s.scans_in, 896u);
    // 0 to 2 pi in 360 beams (rplidar_ros's angles): every scan usable.
    EXPECT_EQ(s.scans_skipped, 0u);
    EXPECT_GT(s.scans_kept, 20u);
    EXPECT_LT(s.scans_kept, 896u);
    // Every other topic copied as it came: the IMU's 3698 messages.
    const auto out = kfd::listSource(d / "out.mcap");
    std::map<std::string, std::size_t> counts;
    for (const auto& st : out.streams) counts[st.name] = st.count;
    EXPECT_EQ(counts["/imu_data"], 3698u);
    EXPECT_EQ(counts["/scan"], s.scans_kept);
}

namespace {

// `file` read by npm's readers (test/support/node/read_ros2.js): JSON, or null when they are not
// installed (scripts/ci/npm-peers.sh).
nlohmann::json readWithNpm(const std::string& file, const std::string& out) {
    const std::string peers = KFD_NPM_PEERS_DIR;
    if (!fs::exists(peers + "/@mcap/core") || std::system("command -v node >/dev/null") != 0)
        return nullptr;
    const std::string cmd = "NODE_PATH='" + peers + "' node '" + KFD_SOURCE_DIR +
                            "/test/support/node/read_ros2.js' '" + file + "' /scan > '" + out + "'";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    return nlohmann::json::parse(kfd::test::fileBytes(out));
}

}  // namespace

TEST(Ros2Logs, NpmsMcapAndRosbag2ReadersReadKfdsOutputs) {
    const std::string bag = kMumble + "/hallway_room_loop";
    if (!fs::exists(bag)) GTEST_SKIP() << "dataset missing: " << bag;
    kfd::test::TempDir d("ros2_");
    using C = kfd::BagWriterOptions::Compression;
    const auto s = filter(bag, d / "out.mcap", "");  // as the input: no compression
    filter(bag, d / "out.db3", "");
    filter(bag, d / "zstd.mcap", "", C::Zstd);
    filter(bag, d / "lz4.mcap", "", C::Lz4);
    const auto mcap = readWithNpm(d / "out.mcap", d / "mcap.json");
    if (mcap.is_null())
        GTEST_SKIP() << "npm's readers not installed (bash scripts/ci/npm-peers.sh) or no node";
    const auto db3 = readWithNpm(d / "out.db3", d / "db3.json");
    const auto zstd = readWithNpm(d / "zstd.mcap", d / "zstd.json");
    const auto lz4 = readWithNpm(d / "lz4.mcap", d / "lz4.json");
    for (const auto* j : {&mcap, &db3, &zstd, &lz4}) {
        EXPECT_EQ((*j)["topics"]["/scan"]["type"], "sensor_msgs/msg/LaserScan");
        EXPECT_EQ((*j)["topics"]["/scan"]["count"], s.scans_kept);
        EXPECT_EQ((*j)["topics"]["/imu_data"]["count"], 3698);
    }
    // MCAP's summary as a seeking reader uses it: every message through the chunk indexes.
    for (const auto* j : {&mcap, &zstd, &lz4}) {
        EXPECT_EQ((*j)["indexed"]["messages"], s.scans_kept + 3698);
        EXPECT_EQ((*j)["indexed"]["statistics"], s.scans_kept + 3698);
    }
    // The readers see the same scans in every file, and kfd's own reader agrees beam for beam:
    // a valid return is the same float, a NaN (removed, or none) is invalid in kfd.
    ASSERT_EQ(mcap["scans"], db3["scans"]);
    ASSERT_EQ(zstd["scans"], db3["scans"]);
    ASSERT_EQ(lz4["scans"], db3["scans"]);
    const auto kfd_rows = scansOf(d / "out.mcap");
    ASSERT_EQ(mcap["scans"].size(), kfd_rows.size());
    std::size_t nan = 0;
    for (std::size_t i = 0; i < kfd_rows.size(); ++i) {
        const auto& js = mcap["scans"][i];
        EXPECT_NEAR(js["sec"].get<double>() + js["nanosec"].get<double>() * 1e-9, kfd_rows[i].t,
                    1e-6);
        const auto& r = js["ranges"];
        ASSERT_EQ(r.size(), kfd_rows[i].ranges.size());
        for (std::size_t k = 0; k < r.size(); ++k) {
            if (kfd_rows[i].valid[k]) {
                EXPECT_EQ(r[k].get<float>(), kfd_rows[i].ranges[k]);
            }
            if (r[k].is_null()) {
                EXPECT_FALSE(kfd_rows[i].valid[k]);
                ++nan;
            }
        }
    }
    EXPECT_GE(nan, s.points_marked);
}

// --- bad input: a clear error naming the file, nothing left behind -------------------------

namespace {

void expectRefused(const std::string& in, const std::string& words) {
    const std::string out = in + ".out.rawlog";
    try {
        filter(in, out, "");
        ADD_FAILURE() << in << " was read";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(out));
}

std::string bytesOf(const std::string& p) { return kfd::test::fileBytes(p); }

}  // namespace

TEST(Ros2Logs, BadFilesAreRefusedWithAClearMessage) {
    kfd::test::TempDir d("ros2_");
    {
        rosbag::Bag bag(d / "in.bag", rosbag::bagmode::Write);
        for (int i = 0; i < 20; ++i) {
            const auto s = tinyScan(100.0 + 0.1 * i, 1.0f + 0.01f * i);
            bag.write("/scan", s.header.stamp, s);
        }
    }
    convert(d / "in.bag", d / "ok.db3");
    convert(d / "in.bag", d / "ok.mcap");
    const std::string db = bytesOf(d / "ok.db3"), mcap = bytesOf(d / "ok.mcap");

    // sqlite: a file whose pages are garbage after the header.
    std::string corrupt = db;
    for (std::size_t i = 100; i < corrupt.size(); i += 7) corrupt[i] = static_cast<char>(0xA5);
    write(d / "corrupt.db3", corrupt);
    expectRefused(d / "corrupt.db3", "corrupt.db3");
    // sqlite: cut in half.
    write(d / "half.db3", db.substr(0, db.size() / 2));
    expectRefused(d / "half.db3", "half.db3");
    // rosbag2 folder: metadata.yaml that is not rosbag2's, one that lists a missing file, a
    // compressed bag.
    fs::create_directories(d / "f1");
    write(d / "f1/metadata.yaml", "hello: [1, 2\n");
    expectRefused(d / "f1", "metadata.yaml");
    fs::create_directories(d / "f2");
    write(d / "f2/metadata.yaml",
          "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  relative_file_paths:\n"
          "    - gone_0.db3\n");
    expectRefused(d / "f2", "missing");
    fs::create_directories(d / "f3");
    write(d / "f3/metadata.yaml",
          "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n  compression_format: "
          "zstd\n  compression_mode: FILE\n  relative_file_paths:\n    - x_0.db3.zstd\n");
    expectRefused(d / "f3", "ros2 bag decompress");
    // MCAP: truncated, a record length that lies, an unknown chunk compression.
    write(d / "cut.mcap", mcap.substr(0, mcap.size() * 2 / 3));
    expectRefused(d / "cut.mcap", "cut.mcap: byte");
    std::string lies = mcap;
    const std::size_t header_len_at = 8 + 1;  // the Header record's length field
    lies[header_len_at + 6] = static_cast<char>(0x7f);
    write(d / "lies.mcap", lies);
    expectRefused(d / "lies.mcap", "past the file's end");
    // A chunk record with compression "brotli", written by hand.
    std::string chunk;
    auto u64 = [](std::uint64_t v) {
        std::string s(8, '\0');
        for (int i = 0; i < 8; ++i) s[i] = static_cast<char>(v >> (8 * i));
        return s;
    };
    auto u32 = [](std::uint32_t v) {
        std::string s(4, '\0');
        for (int i = 0; i < 4; ++i) s[i] = static_cast<char>(v >> (8 * i));
        return s;
    };
    const std::string content =
        u64(0) + u64(0) + u64(4) + u32(0) + u32(6) + "brotli" + u64(4) + "abcd";
    const std::string brotli = mcap.substr(0, 8) + std::string(1, '\x06') + u64(content.size()) +
                               content + std::string(1, '\x0F') + u64(4) + u32(0);
    write(d / "brotli.mcap", brotli);
    expectRefused(d / "brotli.mcap", "brotli");
}

namespace {
std::size_t openDescriptors() {
    return static_cast<std::size_t>(
        std::distance(fs::directory_iterator("/proc/self/fd"), fs::directory_iterator()));
}
}  // namespace

// A refused file leaves nothing open: each bad MCAP once kept its FILE (and descriptor).
TEST(Ros2Logs, RefusedFilesLeaveNoDescriptorOpen) {
    kfd::test::TempDir d("ros2_");
    write(d / "bad.mcap", std::string("\x89MCAP0\r\n", 8) + "\x01" + std::string(7, '\xff'));
    write(d / "bad.db3", std::string("SQLite format 3\0", 16) + std::string(100, 'x'));
    const std::size_t before = openDescriptors();
    for (int i = 0; i < 50; ++i)
        for (const char* f : {"bad.mcap", "bad.db3"}) {
            EXPECT_THROW(kfd::BagSource{d / f}, kfd::BagError);
            EXPECT_THROW(kfd::Ros2Writer(d / "no/such/dir/out.mcap", kfd::LogFormat::Mcap),
                         kfd::BagError);
        }
    EXPECT_EQ(openDescriptors(), before);
}
