// Corrupt length fields in bags, rawlogs and CARMEN logs: an error, never gigabytes allocated.
#include "app_runner.h"
#include "bad_logs.h"

namespace {

using namespace kfd::test::apps;

// --- corrupt length fields (issue 21) ---

// The apps' normal use takes ~70 MB resident (their address space is larger: libraries, thread
// stacks); a corrupt length field made them allocate 8-24 GB. Each row runs under this limit.
constexpr rlim_t kOneGiB = rlim_t{1} << 30;

// kfd-filter and kfd-icp-slam on an input with a corrupt length field, under a 1 GiB
// address-space limit: exit 1 with `message` as the whole first line (after "APP: "), nothing
// left in the folder, the input unchanged.
void expectCorruptLengthRefused(const Dir& d, const std::string& in, const std::string& message,
                                const std::string& out) {
    SCOPED_TRACE(in);
    const auto before = listing(d.path);
    const Snapshot snap({in});
    Result r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / out, "--stats", d / "s.csv"}, d.path,
                   kOneGiB);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.first(), "kfd-filter: " + message);
    r = run(KFD_ICP_SLAM_EXE, {"-q", kSlamIni, in, "-o", d / "slam", "--no-map"}, d.path, kOneGiB);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.first(), "kfd-icp-slam: " + message);
    EXPECT_EQ(listing(d.path), before);
    snap.expectUnchanged();
}

// writeBag's bag (uncompressed, 40 scans of 181 beams, odometry) with scan k as `bad`.
std::string writeBagWith(const Dir& d, const std::string& name, int k,
                         const kfd::test::Serialized<sensor_msgs::LaserScan>& bad) {
    const std::string p = d / name;
    kfd::test::BagBuilder b(p);
    for (int i = 0; i < 40; ++i) {
        b.odom("/odom", 1 + 0.2 * i, 0.05 * i, 0, 0);
        if (i == k)
            b.raw("/scan", 1 + 0.2 * i + 0.1, bad);
        else
            b.scan("/scan", kfd::test::BagBuilder::scanMsg(1 + 0.2 * i + 0.1,
                                                           std::vector<float>(181, 2.0f)));
    }
    return p;
}

TEST(CorruptLength, BagScanRangesLengthIsAnErrorNotGigabytes) {
    // 0x40000000 made kfd-filter allocate 8.4 GB, 0xFFFFFFFF over 16 GiB.
    Dir d;
    const auto scan = kfd::test::BagBuilder::scanMsg(2.1, std::vector<float>(181, 2.0f));
    const auto good = kfd::test::serialized(scan);
    const std::size_t at = kfd::test::rangesLengthAt(scan);
    const std::string sizes = " does not fit in the message's " +
                              std::to_string(good.bytes.size()) + " bytes (" +
                              std::to_string(good.bytes.size() - at - 4) + " left)";
    const auto later = writeBagWith(d, "later.bag", 5, kfd::test::withU32(good, at, 0x40000000u));
    expectCorruptLengthRefused(
        d, later,
        later +
            ": message 12 (/scan at t = 2.100000 s): corrupt sensor_msgs/LaserScan: ranges: "
            "array length 1073741824 (4294967296 bytes)" +
            sizes,
        "out.bag");
    // The first scan is read when the bag is opened (its frame names the mount).
    const auto first = writeBagWith(d, "first.bag", 0, kfd::test::withU32(good, at, 0xffffffffu));
    expectCorruptLengthRefused(d, first,
                               first +
                                   ": the message on /scan at t = 1.100000 s: corrupt "
                                   "sensor_msgs/LaserScan: ranges: array length 4294967295 "
                                   "(17179869180 bytes)" +
                                   sizes,
                               "out.bag");
}

TEST(CorruptLength, BagWithFlippedMessageBytesIsAnErrorNotGigabytes) {
    // An uncompressed bag with 16 bytes of one scan message flipped (scan_time, range_min,
    // range_max and the ranges length): the structure check cannot see it; roscpp resized the
    // ranges to 1.5 G floats (6 GB) before its "Buffer Overrun".
    Dir d;
    std::string bytes = kfd::test::fileBytes(writeBag(d, "good.bag"));
    fs::remove(d / "good.bag");
    std::vector<float> ranges(181);  // writeBag's seventh scan
    for (std::size_t k = 0; k < ranges.size(); ++k)
        ranges[k] = 2.0f + 0.01f * static_cast<float>(k % 7);
    const auto scan = kfd::test::BagBuilder::scanMsg(1 + 0.2 * 7 + 0.1, ranges);
    const auto msg = kfd::test::serialized(scan);
    const auto at = bytes.find(std::string(msg.bytes.begin(), msg.bytes.end()));
    ASSERT_NE(at, std::string::npos);
    const std::size_t ranges_at = kfd::test::rangesLengthAt(scan);
    for (std::size_t i = at + ranges_at - 12; i < at + ranges_at + 4; ++i)
        bytes[i] = static_cast<char>(bytes[i] ^ 0x5a);
    const auto in = d.write("flipped.bag", bytes);
    const std::uint32_t count = 181u ^ 0x5a5a5a5au;
    expectCorruptLengthRefused(
        d, in,
        in +
            ": message 16 (/scan at t = 2.500000 s): corrupt "
            "sensor_msgs/LaserScan: ranges: array length " +
            std::to_string(count) + " (" + std::to_string(std::uint64_t{count} * 4) +
            " bytes) does not fit in the message's " + std::to_string(msg.bytes.size()) +
            " bytes (" + std::to_string(msg.bytes.size() - ranges_at - 4) + " left)",
        "out.bag");
}

TEST(CorruptLength, RawlogScanBeamCountIsAnErrorNotGigabytes) {
    // The first scan's beam count: 0x40000000 made MRPT size its three arrays (9.5 GB), and
    // under a memory limit segfault in its allocator, leaving a temporary output file.
    const std::string data = plainOffice();
    const std::size_t at = kfd::test::scanBeamCountAt(data.find("LASER"), 1081);
    ASSERT_EQ(data.substr(at, 4), std::string("\x39\x04\0\0", 4));  // 1081 beams
    for (const std::uint32_t count : {0x40000000u, 0xffffffffu}) {
        Dir d;
        const auto in = d.write("in.rawlog", kfd::test::withU32(data, at, count));
        expectCorruptLengthRefused(d, in,
                                   "cannot read object #0 of " + in +
                                       ": an object claims more memory than the " +
                                       std::to_string(data.size() - at - 4) +
                                       " bytes left in the file (a corrupt length field)",
                                   "out.rawlog");
    }
}

TEST(CorruptLength, FuzzFindingsAreClearErrors) {
    // What fuzzing found (test/fuzz/corpus/*/finding-*): a connection header whose field runs
    // past it (rosbag's parser read beyond its buffer), and an image observation asking OpenCV
    // for 1.2e18 bytes through malloc, outside kfd's allocation bound.
    const std::string corpus = std::string(KFD_SOURCE_DIR) + "/test/fuzz/corpus/";
    Dir d;
    const auto bag =
        d.write("in.bag", fileBytes(corpus + "bag/finding-connection-header-field-length.bag"));
    expectCorruptLengthRefused(
        d, bag, bag + ": byte 23586: a header field is longer than its header", "out.bag");
    const std::string image = fileBytes(corpus + "rawlog/finding-opencv-image-size.rawlog");
    const auto rawlog = d.write("in.rawlog", image);
    const std::string says =
        "cannot read object #0 of " + rawlog + ": an object claims more memory than the ";
    const Snapshot snap({rawlog});
    for (const std::string exe : {KFD_FILTER_EXE, KFD_ICP_SLAM_EXE}) {
        const auto before = listing(d.path);
        const bool filter = exe == KFD_FILTER_EXE;
        const Result r =
            filter
                ? run(exe, {"-q", "-i", rawlog, "-o", d / "out.rawlog"}, d.path, kOneGiB)
                : run(exe, {"-q", kSlamIni, rawlog, "-o", d / "slam", "--no-map"}, d.path, kOneGiB);
        EXPECT_EQ(r.status, 1) << r.err;
        EXPECT_EQ(r.first().rfind((filter ? "kfd-filter: " : "kfd-icp-slam: ") + says, 0), 0u)
            << r.first();
        EXPECT_NE(r.first().find("(a corrupt length field)"), std::string::npos) << r.first();
        EXPECT_EQ(listing(d.path), before);
    }
    snap.expectUnchanged();
}

TEST(CorruptLength, CarmenReadingCountIsAnErrorNotGigabytes) {
    Dir d;
    const auto in = d.write("in.clf",
                            "ODOM 0 0 0 0 0 0 1.0 h 0\n"
                            "FLASER 1073741824 1 2 0 0 0 0 0 0 5.0 h 0\n");
    expectCorruptLengthRefused(
        d, in, in + ":2: FLASER reading count 1073741824 is more than the 11 fields after it",
        "out.rawlog");
}

}  // namespace
