// A full file system under every output: a clear error, nothing half-written left.
#include "app_runner.h"
#include "bad_logs.h"

namespace {

using namespace kfd::test::apps;

// --- a full file system (issue 21) ---

// The size of the tmpfs the full-disk rows write into: every output below is larger (each row
// proves it with the same run into a roomy folder first).
constexpr std::uintmax_t kTmpfsBytes = 32 * 1024;

// A tmpfs of `bytes` (kTmpfsBytes) mounted on `dir` (created) while the row runs. Mounting
// needs root (CAP_SYS_ADMIN); without it `mounted` is false and `why` says why.
struct SmallTmpfs {
    fs::path dir;
    bool mounted = false;
    std::string why;
    explicit SmallTmpfs(fs::path at, std::uintmax_t bytes = kTmpfsBytes) : dir(std::move(at)) {
        fs::create_directories(dir);
        const std::string options = "size=" + std::to_string(bytes);
        if (mount("tmpfs", dir.c_str(), "tmpfs", MS_NOSUID | MS_NODEV, options.c_str()) == 0)
            mounted = true;
        else
            why = std::strerror(errno);
    }
    ~SmallTmpfs() {
        if (mounted) umount2(dir.c_str(), MNT_DETACH);
    }
    SmallTmpfs(const SmallTmpfs&) = delete;
    SmallTmpfs& operator=(const SmallTmpfs&) = delete;
};

#define KFD_REQUIRE_TMPFS(t)                                                       \
    if (!(t).mounted)                                                              \
    GTEST_SKIP() << "cannot mount a small tmpfs on " << (t).dir << " (" << (t).why \
                 << "): the full-disk rows need root (CAP_SYS_ADMIN)"

// The bytes of the regular files under `dir`.
std::uintmax_t bytesUnder(const fs::path& dir) {
    std::uintmax_t n = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file()) n += e.file_size();
    return n;
}

// One full-disk row: `args(folder)` writes the app's outputs into `folder`. The same run into a
// roomy folder succeeds and writes more than the tmpfs holds; into the full tmpfs it exits 1, its
// first line is "APP: cannot write FULL/FILE...: No space left on device" (FILE starting with
// `file`), libpng prints nothing, and nothing is left on the tmpfs (nor, with `also_empty`,
// there). The inputs are unchanged.
void expectFullDiskRow(const Dir& d, const SmallTmpfs& t, const std::string& exe,
                       const std::string& app,
                       const std::function<std::vector<std::string>(const fs::path&)>& args,
                       const std::string& file, const std::vector<std::string>& inputs) {
    SCOPED_TRACE(app + " " + file);
    const Snapshot snap(inputs);
    const fs::path roomy = d.path / "roomy";
    fs::create_directories(roomy);
    Result r = run(exe, args(roomy), d.path);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_GT(bytesUnder(roomy), kTmpfsBytes) << "the outputs would fit: the row fills nothing";
    fs::remove_all(roomy);
    r = run(exe, args(t.dir), d.path);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.first().rfind(app + ": cannot write " + (t.dir / file).string(), 0), 0u) << r.err;
    EXPECT_NE(r.first().find(": No space left on device"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("libpng"), std::string::npos) << r.err;
    EXPECT_TRUE(listing(t.dir).empty());
    snap.expectUnchanged();
}

TEST(FullDisk, FilterRawlogAndStatsFile) {
    Dir d;
    SmallTmpfs t(d.path / "full");
    KFD_REQUIRE_TMPFS(t);
    const auto in = d.copy(kOffice, "in.rawlog");
    // The output, uncompressed (--compress 0): 336 kB.
    expectFullDiskRow(d, t, KFD_FILTER_EXE, "kfd-filter",
                      [&](const fs::path& o) {
                          return std::vector<std::string>{
                              "-q", "-i", in, "-o", o / "out.rawlog", "--compress", "0"};
                      },
                      "out.rawlog: ", {in});
    // The stats file (80 kB) on the full tmpfs, the output elsewhere: neither is left.
    const Snapshot snap({in});
    const Result r =
        run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / "out.rawlog", "--stats", t.dir / "s.csv"},
            d.path);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.first(), "kfd-filter: cannot write " + (t.dir / "s.csv").string() +
                             ": No space left on device");
    EXPECT_TRUE(listing(t.dir).empty());
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"in.rawlog", "full"}));
    snap.expectUnchanged();
}

TEST(FullDisk, FilterWhoseLastBytesDoNotFit) {
    // The case: everything fits but the end of the gzip stream, written when the output
    // is closed (CFileGZOutputStream ignored that error: exit 0, a cut-short gzip in place).
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    fs::create_directory(d / "roomy");
    Result r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / "roomy/out.rawlog"}, d.path);
    ASSERT_EQ(r.status, 0) << r.err;
    const std::uintmax_t size = fs::file_size(d / "roomy/out.rawlog");
    fs::remove_all(d / "roomy");
    ASSERT_GT(size, 2 * 65536u);  // several full buffers go out before the last one
    SmallTmpfs t(d.path / "full", (size - 1) / 4096 * 4096);  // whole pages, one byte short
    KFD_REQUIRE_TMPFS(t);
    r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", t.dir / "out.rawlog"}, d.path);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.first(), "kfd-filter: cannot write " + (t.dir / "out.rawlog").string() +
                             ": No space left on device");
    EXPECT_TRUE(listing(t.dir).empty());
    snap.expectUnchanged();
}

TEST(FullDisk, FilterBagOutput) {
    Dir d;
    SmallTmpfs t(d.path / "full");
    KFD_REQUIRE_TMPFS(t);
    const auto in = writeBag(d, "in.bag", 400);
    expectFullDiskRow(d, t, KFD_FILTER_EXE, "kfd-filter",
                      [&](const fs::path& o) {
                          return std::vector<std::string>{
                              "-q", "-i", in, "-o", o / "out.bag", "--bag-compression", "none"};
                      },
                      "out.bag: ", {in});
}

TEST(FullDisk, FilterCarmenOutput) {
    Dir d;
    SmallTmpfs t(d.path / "full");
    KFD_REQUIRE_TMPFS(t);
    const auto in = d.copy(kOffice, "in.rawlog");
    for (const char* name : {"out.clf", "out.clf.gz"})
        expectFullDiskRow(d, t, KFD_FILTER_EXE, "kfd-filter",
                          [&](const fs::path& o) {
                              return std::vector<std::string>{"-q",     "-i",         in, "-o",
                                                              o / name, "--compress", "0"};
                          },
                          std::string(name) + ": ", {in});
}

TEST(FullDisk, IcpSlamOutputFolder) {
    Dir d;
    SmallTmpfs t(d.path / "full");
    KFD_REQUIRE_TMPFS(t);
    const auto in = d.copy(kOffice, "in.rawlog");
    const auto cfg = d.copy(kSlamIni, "slam.ini");
    expectFullDiskRow(d, t, KFD_ICP_SLAM_EXE, "kfd-icp-slam",
                      [&](const fs::path& o) {
                          return std::vector<std::string>{"-q", cfg, in, "-o", o / "slam"};
                      },
                      "slam/", {in, cfg});
}

TEST(FullDisk, IcpSlamThreeDScenes) {
    // icp-slam's periodic files (SAVE_3D_SCENE every step) go through kfd's checked writers
    // too: the scenes fill the tmpfs first, and the error names the scene that did not fit.
    Dir d;
    SmallTmpfs t(d.path / "full");
    KFD_REQUIRE_TMPFS(t);
    const auto in = d.copy(kOffice, "in.rawlog");
    std::string ini = fileBytes(kSlamIni);
    for (const std::string key : {"LOG_FREQUENCY = 0", "SAVE_3D_SCENE = 0"}) {
        const auto at = ini.find(key);
        ASSERT_NE(at, std::string::npos) << key;
        ini[at + key.size() - 1] = '1';
    }
    const auto cfg = d.write("slam.ini", ini);
    expectFullDiskRow(d, t, KFD_ICP_SLAM_EXE, "kfd-icp-slam",
                      [&](const fs::path& o) {
                          return std::vector<std::string>{"-q", "--no-map", cfg,
                                                          in,   "-o",       o / "slam"};
                      },
                      "slam/buildingmap_", {in, cfg});
}

TEST(FullDisk, SimulateAndInject) {
    Dir d;
    SmallTmpfs t(d.path / "full");
    KFD_REQUIRE_TMPFS(t);
    expectFullDiskRow(d, t, KFD_SIMULATE_EXE, "kfd-simulate",
                      [&](const fs::path& o) {
                          return std::vector<std::string>{"-q", "-o", o / "sim.rawlog", "-d", "5"};
                      },
                      "sim.", {});
    const auto in = d.copy(kOffice, "in.rawlog");
    expectFullDiskRow(d, t, KFD_INJECT_EXE, "kfd-inject",
                      [&](const fs::path& o) {
                          return std::vector<std::string>{"-q", "-i", in, "-o", o / "noisy.rawlog"};
                      },
                      "noisy.", {in});
}

TEST(FullDisk, ChartAndRenderImages) {
    Dir d;
    SmallTmpfs t(d.path / "full");
    KFD_REQUIRE_TMPFS(t);
    const auto csv = d.write("bars.csv", "group,series,value\na,x,1\na,y,2\nb,x,3\n");
    expectFullDiskRow(d, t, KFD_CHART_EXE, "kfd-chart",
                      [&](const fs::path& o) {
                          return std::vector<std::string>{csv,      "-o",   o / "bars.png",
                                                          "--size", "3000", "2000"};
                      },
                      "bars.png: ", {csv});
#ifdef KFD_RENDER_EXE
    const auto in = d.copy(kOffice, "in.rawlog");
    expectFullDiskRow(d, t, KFD_RENDER_EXE, "kfd-render",
                      [&](const fs::path& o) {
                          return std::vector<std::string>{"-i",  in,   "--index",
                                                          "300", "-o", o / "scan.png"};
                      },
                      "scan.png: ", {in});
#endif
}

}  // namespace
