// ROS bags and CARMEN logs: truncated, corrupt, missing topics, unsupported types, outputs
// of a format kfd does not write.
#include "app_runner.h"
#include "bad_logs.h"

namespace {

using namespace kfd::test::apps;

// --- ROS bags and CARMEN logs (issue 13) ---

TEST(BadBagsAndCarmen, TruncatedOrCorruptBagsAreRefused) {
    Dir d;
    const std::string bytes = fileBytes(writeBag(d, "good.bag"));
    fs::remove(d / "good.bag");
    const auto cut = d.write("cut.bag", bytes.substr(0, bytes.size() / 2));
    expectLogRefused(d, cut, {}, "truncated");
    std::string bad = bytes;
    for (std::size_t i = bad.size() - 120; i < bad.size(); ++i) bad[i] ^= 0x5a;  // the index
    const auto corrupt = d.write("corrupt.bag", bad);
    expectLogRefused(d, corrupt, {}, ": byte ");
    const auto text = d.write("text.bag", "not a bag\n");
    expectLogRefused(d, text, {}, "not a ROS bag");
}

// Issue 23: a chunk's contents are checked when kfd first reads it (each chunk is decompressed
// once), so a chunk that does not decompress is found while the outputs are being written: the
// same refusal, and nothing is left behind.
TEST(BadBagsAndCarmen, AChunkThatDoesNotDecompressIsRefusedWhenRead) {
    Dir d;
    const std::string p = d / "good.bag";
    {
        kfd::test::BagBuilder b(p, rosbag::compression::BZ2);
        for (int i = 0; i < 400; ++i) {
            b.odom("/odom", 1 + 0.1 * i, 0.01 * i, 0, 0);
            b.scan("/scan", kfd::test::BagBuilder::scanMsg(1 + 0.1 * i + 0.05,
                                                           kfd::test::room(0.01 * i, 0, 0, 361)));
        }
    }
    std::string bytes = fileBytes(p);
    fs::remove(p);
    // The middle of the last chunk's bz2 stream.
    const auto last = bytes.rfind("compression=bz2");
    ASSERT_NE(last, std::string::npos);
    const auto bz = bytes.find("BZh", last);
    ASSERT_NE(bz, std::string::npos);
    for (std::size_t i = bz + 2000; i < bz + 2064; ++i) bytes[i] ^= 0x5a;
    const auto bad = d.write("bad.bag", bytes);
    expectLogRefused(d, bad, {}, "chunk does not decompress");
}

// Issue 23: the filtered bag's chunks are compressed like the input's unless --bag-compression
// names a compression.
TEST(BadBagsAndCarmen, AFilteredBagIsCompressedLikeItsInput) {
    Dir d;
    const auto& kinds = kfd::test::bagCompressions();
    for (const auto& [c, name] : kinds) {
        SCOPED_TRACE(name);
        const std::string in = d / ("in-" + name + ".bag");
        {
            kfd::test::BagBuilder b(in, c);
            for (int i = 0; i < 40; ++i) {
                b.odom("/odom", 1 + 0.2 * i, 0.05 * i, 0, 0);
                b.scan("/scan", kfd::test::BagBuilder::scanMsg(
                                    1 + 0.2 * i + 0.1, kfd::test::room(0.05 * i, 0, 0, 181)));
            }
        }
        const std::string out = d / ("out-" + name + ".bag");
        Result r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", out}, d.path);
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(kfd::test::chunkCompressions(out), std::set<std::string>{name});
        const std::string told = name == "lz4" ? "bz2" : "lz4";
        r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", out, "--bag-compression", told}, d.path);
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(kfd::test::chunkCompressions(out), std::set<std::string>{told});
    }
}

TEST(BadBagsAndCarmen, MissingTopicsAndUnsupportedTypesAreRefused) {
    Dir d;
    const auto bag = writeBag(d, "in.bag");
    expectLogRefused(d, bag, {"--scan-topic", "/base_scan"},
                     "--scan-topic /base_scan: no such topic");
    expectLogRefused(d, bag, {"--scan-topic", "/odom"},
                     "the topic holds nav_msgs/Odometry, not sensor_msgs/LaserScan");
    expectLogRefused(d, bag, {"--odom-topic", "/scan"},
                     "the topic holds sensor_msgs/LaserScan, not nav_msgs/Odometry");
    const std::string odom_only = d / "odom.bag";
    {
        kfd::test::BagBuilder b(odom_only);
        b.odom("/odom", 1, 0, 0, 0);
    }
    expectLogRefused(d, odom_only, {}, "no sensor_msgs/LaserScan topic");
}

TEST(BadBagsAndCarmen, CarmenLinesWithTheWrongFieldCountAreRefused) {
    Dir d;
    const auto clf =
        d.write("x.clf", "FLASER 2 1 2 0 0 0 0 0 0 5.0 h 0\nFLASER 3 1 2 0 0 0 0 0 0 6.0 h 0\n");
    expectLogRefused(d, clf, {}, clf + ":2: FLASER with 3 readings has 13 fields, expected 14",
                     "out.rawlog");
    const auto num = d.write("y.log", "ODOM 1 2 x 0 0 0 5.0 h 0\n");
    expectLogRefused(d, num, {}, ":1: ODOM field 3 ('x') is not a number", "out.rawlog");
}

TEST(BadBagsAndCarmen, ABagOutputNeedsABagInput) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    const Result r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / "out.bag"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.first().find("a bag output (" + (d / "out.bag") + ") needs a ROS 1 bag input"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    snap.expectUnchanged();
}

// Issue 23: an output is written in the format its name says, or refused. Before, any name
// but .bag got an MRPT rawlog (`-o y.clf` and `-o y.txt`: a rawlog, exit 0).
TEST(BadBagsAndCarmen, AnOutputNameOfNoFormatKfdWritesIsRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    for (const std::string name : {"y.txt", "y", "y.clf.txt"}) {
        const Result r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / name}, d.path);
        EXPECT_EQ(r.status, 1) << name;
        EXPECT_EQ(r.first(), "kfd-filter: the output " + (d / name) +
                                 ": kfd-filter writes .rawlog (an MRPT rawlog), .bag (a ROS 1 "
                                 "bag, for a ROS 1 bag input), .db3 or .mcap (ROS 2, for any "
                                 "bag input), .clf or .log (a CARMEN log; .clf.gz, .log.gz: "
                                 "gzip); its name says none of them")
            << r.err;
    }
    // kfd-simulate and kfd-inject write rawlogs only.
    for (const auto& [exe, app] :
         {std::pair{KFD_SIMULATE_EXE, "kfd-simulate"}, std::pair{KFD_INJECT_EXE, "kfd-inject"}}) {
        const std::string out = d / "y.clf";
        const Result r = std::string(app) == "kfd-inject"
                             ? run(exe, {"-q", "-i", in, "-o", out}, d.path)
                             : run(exe, {"-q", "-o", out, "-d", "1"}, d.path);
        EXPECT_EQ(r.status, 1) << app;
        EXPECT_EQ(r.first(), std::string(app) + ": the output rawlog " + out + ": " + app +
                                 " writes an MRPT rawlog (.rawlog); its name says none of them")
            << r.err;
    }
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    snap.expectUnchanged();
}

TEST(BadBagsAndCarmen, AClfOrLogOutputIsACarmenLog) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    for (const std::string name : {"out.clf", "out.log"}) {
        const Result r = run(KFD_FILTER_EXE, {"-i", in, "-o", d / name}, d.path);
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_NE(r.out.find("output   " + (d / name) + " (CARMEN log)"), std::string::npos)
            << r.out;
        EXPECT_EQ(kfd::detectFormat(d / name), kfd::LogFormat::Carmen);
        const std::string text = fileBytes(d / name);
        EXPECT_EQ(text.rfind("# CARMEN log written by kfd\n", 0), 0u);
        EXPECT_NE(text.find("\nFLASER 1081 "), std::string::npos);
        EXPECT_NE(text.find("\nODOM "), std::string::npos);
    }
    // A log without odometry cannot be a CARMEN log (a FLASER line holds the odometry).
    const auto raw = d.write("raw.log", "RAWLASER1 0 -1.5 3 0.01 8 0.01 0 3 1 2 3 0 10 h 0\n");
    const Result r = run(KFD_FILTER_EXE, {"-q", "-i", raw, "-o", d / "nodo.clf"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first().rfind("kfd-filter: a CARMEN output needs the robot's odometry", 0), 0u)
        << r.err;
    EXPECT_EQ(listing(d.path),
              (std::set<std::string>{"in.rawlog", "out.clf", "out.log", "raw.log"}));
    snap.expectUnchanged();
}

}  // namespace
