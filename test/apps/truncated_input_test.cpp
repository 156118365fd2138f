// Truncated and corrupt gzip inputs: errors naming the file, never a partial output.
#include "app_runner.h"
#include "bad_logs.h"

namespace {

using namespace kfd::test::apps;

// --- truncated input ---

// kfd-filter on a damaged copy of a gzip rawlog: exit 1, the reason, nothing written.
void expectFilterRefuses(const std::string& bytes, const std::string& reason) {
    Dir d;
    const auto in = d.write("in.rawlog", bytes);
    const Snapshot snap({in});
    const Result r = run(KFD_FILTER_EXE,
                         {"-q", "-i", in, "-o", d / "out.rawlog", "--stats", d / "s.csv"}, d.path);
    EXPECT_EQ(r.status, 1);
    expectGzipRefusal(r.first(), "kfd-filter", in, reason);
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    snap.expectUnchanged();
}

TEST(TruncatedInput, GzipWithoutItsTrailerIsAnError) {
    const std::string data = fileBytes(kOffice);
    expectFilterRefuses(data.substr(0, data.size() - 8), "the gzip stream ends early");
}

TEST(TruncatedInput, GzipWithAWrongCrcIsAnError) {
    std::string data = fileBytes(kOffice);
    data[data.size() - 8] = static_cast<char>(data[data.size() - 8] ^ 0x01);
    expectFilterRefuses(data, "incorrect data check");
}

TEST(TruncatedInput, GzipWithAWrongLengthIsAnError) {
    std::string data = fileBytes(kOffice);
    data[data.size() - 1] = static_cast<char>(data[data.size() - 1] ^ 0x01);
    expectFilterRefuses(data, "incorrect length check");
}

TEST(TruncatedInput, GarbageAfterTheGzipStreamIsAnError) {
    expectFilterRefuses(fileBytes(kOffice) + "garbage", "garbage after the gzip stream");
}

TEST(TruncatedInput, ACorruptLengthFieldIsAnErrorNotGigabytes) {
    // The first scan's sensor label length claims 4 GiB (MRPT alone zero-fills a 4 GiB string
    // first: 4.2 GB resident). kfd-filter refuses the object, names the cause, writes nothing.
    std::string data = plainOffice();
    const std::size_t at = data.find("LASER");
    ASSERT_NE(at, std::string::npos);
    ASSERT_EQ(data.substr(at - 4, 4), std::string("\x05\0\0\0", 4));
    data.replace(at - 4, 4, std::string("\xf0\xff\xff\xff", 4));
    Dir d;
    const auto in = d.write("in.rawlog", data);
    const Snapshot snap({in});
    const Result r = run(KFD_FILTER_EXE,
                         {"-q", "-i", in, "-o", d / "out.rawlog", "--stats", d / "s.csv"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first().rfind("kfd-filter: cannot read object #0 of " + in, 0), 0u) << r.err;
    EXPECT_NE(r.first().find("(a corrupt length field)"), std::string::npos) << r.err;
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    snap.expectUnchanged();
}

TEST(TruncatedInput, IcpSlamOnATruncatedGzipFailsWithNoOutput) {
    Dir d;
    const std::string data = fileBytes(kOffice);
    const auto in = d.write("in.rawlog", data.substr(0, data.size() - 8));
    const auto cfg = d.copy(kSlamIni, "slam.ini");
    const Snapshot snap({in, cfg});
    const Result r =
        run(KFD_ICP_SLAM_EXE, {"-q", cfg, in, "-o", d / "out", "-m", "none", "--no-map"}, d.path);
    EXPECT_EQ(r.status, 1);
    expectGzipRefusal(r.first(), "kfd-icp-slam", in, "the gzip stream ends early");
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"in.rawlog", "slam.ini"}));
    snap.expectUnchanged();
}

TEST(TruncatedInput, DenoiseEvalAndRenderOnATruncatedLogFail) {
    Dir d;
    const std::string data = fileBytes(kOffice);
    const auto in = d.write("in.rawlog", data.substr(0, data.size() / 2));
    const auto labels =
        d.copy(std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.labels.csv", "l.csv");
    const auto cfg = d.copy(kIni, "kfd.ini");
    const Snapshot snap({in, labels, cfg});
    Result r = run(KFD_DENOISE_EVAL_EXE, {"-i", in, "-l", labels, "-c", cfg}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.first().find("truncated or corrupt"), std::string::npos) << r.err;
#ifdef KFD_RENDER_EXE
    r = run(KFD_RENDER_EXE, {"-i", in, "--index", "1000000", "-o", d / "x.png"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.first().find("truncated or corrupt"), std::string::npos) << r.err;
#endif
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"in.rawlog", "l.csv", "kfd.ini"}));
    snap.expectUnchanged();
}

TEST(TruncatedInput, SimulateOnAGridmapWithoutItsGzipTrailerFails) {
    const std::string grid = std::string(KFD_MRPT_DATASETS_DIR) + "/2006-MalagaCampus.gridmap.gz";
    if (!fs::exists(grid)) GTEST_SKIP() << "MRPT sample gridmap missing: " << grid;
    Dir d;
    const std::string data = fileBytes(grid);
    const auto cut = d.write("g.gridmap.gz", data.substr(0, data.size() - 8));
    const auto route = d.write("route.txt", "0 0\n3 0\n");
    const Snapshot snap({cut, route});
    const Result r =
        run(KFD_SIMULATE_EXE, {"-q", "--gridmap", cut, "--route", route, "-o", d / "sim.rawlog"},
            d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(),
              "kfd-simulate: " + cut +
                  ": the gzip stream ends early (no trailer) (truncated or corrupt file?)");
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"g.gridmap.gz", "route.txt"}));
    snap.expectUnchanged();
}

// kfd-inject: an output on its input, an unknown model, labels that do not name a model.

}  // namespace
