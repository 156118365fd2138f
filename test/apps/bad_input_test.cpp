// The bad-input table (issue 9): each row runs a built app on a bad input and asserts the exit
// status, the first line of the message, that no output (and no temporary file) was left and
// that every input is byte-for-byte unchanged.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <mrpt/io/CFileGZInputStream.h>

#include "bad_logs.h"
#include "kfd/io/open_source.h"
#include "test_bags.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using kfd::test::fileBytes;

// --- Shared helpers: run an app, snapshot files ---------------------------------------------

struct Result {
    int status = -1;  // exit status, or 128 + signal when killed by one
    std::string out, err;
    /// The first line of stderr that the app wrote: a sanitizer runtime's own lines ("==PID==",
    /// e.g. ASan's warning when an impossible malloc returns null in the sanitizer job) are not.
    std::string first() const {
        std::size_t at = 0;
        while (err.compare(at, 2, "==") == 0 && err.find('\n', at) != std::string::npos)
            at = err.find('\n', at) + 1;
        return err.substr(at, err.find('\n', at) - at);
    }
};

// AddressSanitizer reserves terabytes of address space: no RLIMIT_AS under it.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAsan = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAsan = true;
#else
constexpr bool kAsan = false;
#endif
#else
constexpr bool kAsan = false;
#endif

// Starts `exe args...` with stdout and stderr into files under `dir`; returns the pid. A
// non-zero `address_space` limits the app's address space to that many bytes (RLIMIT_AS; not
// under AddressSanitizer).
pid_t spawn(const std::string& exe, const std::vector<std::string>& args, const fs::path& dir,
            rlim_t address_space = 0) {
    const std::string out = (dir / ".stdout").string(), err = (dir / ".stderr").string();
    const pid_t pid = fork();
    if (pid == 0) {
        if (!std::freopen(out.c_str(), "w", stdout) || !std::freopen(err.c_str(), "w", stderr))
            _exit(127);
        const struct rlimit limit { address_space, address_space };
        if (address_space != 0 && !kAsan && setrlimit(RLIMIT_AS, &limit) != 0) _exit(126);
        // The apps leave a signal ignored at their start ignored (nohup): the rows that send
        // signals need the default, whatever the test runner ignores.
        for (const int sig : {SIGINT, SIGTERM, SIGHUP}) signal(sig, SIG_DFL);
        std::vector<char*> argv{const_cast<char*>(exe.c_str())};
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(exe.c_str(), argv.data());
        _exit(127);
    }
    return pid;
}

Result finish(pid_t pid, const fs::path& dir) {
    int ws = 0;
    waitpid(pid, &ws, 0);
    Result r;
    r.status = WIFEXITED(ws) ? WEXITSTATUS(ws) : 128 + WTERMSIG(ws);
    r.out = fileBytes((dir / ".stdout").string());
    r.err = fileBytes((dir / ".stderr").string());
    fs::remove(dir / ".stdout");
    fs::remove(dir / ".stderr");
    return r;
}

// Runs an app to its end (its stdout and stderr are kept in hidden files of `dir` meanwhile),
// optionally under an address-space limit (spawn).
Result run(const std::string& exe, const std::vector<std::string>& args, const fs::path& dir,
           rlim_t address_space = 0) {
    return finish(spawn(exe, args, dir, address_space), dir);
}

// Every file and folder under `dir` (relative paths), hidden ones included.
std::set<std::string> listing(const fs::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        names.insert(e.path().lexically_relative(dir).string());  // symlinks by name
    return names;
}

// The bytes of some files, to prove a run left them unchanged.
struct Snapshot {
    std::map<std::string, std::string> bytes;
    explicit Snapshot(const std::vector<std::string>& paths) {
        for (const auto& p : paths) bytes[p] = fileBytes(p);
    }
    void expectUnchanged() const {
        for (const auto& [p, b] : bytes) EXPECT_TRUE(fileBytes(p) == b) << p << " changed";
    }
};

struct Dir : kfd::test::TempDir {
    Dir() : TempDir("kfd_bad_input_") {}
    // Copies a file into the folder (inputs are copies: a bug must not damage the originals).
    std::string copy(const std::string& from, const std::string& name) const {
        fs::copy_file(from, path / name);
        return (path / name).string();
    }
    std::string write(const std::string& name, const std::string& bytes) const {
        std::ofstream(path / name, std::ios::binary) << bytes;
        return (path / name).string();
    }
};

const std::string kOffice = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";
const std::string kIni = std::string(KFD_SHARE_DIR) + "/default.ini";
const std::string kSlamIni = std::string(KFD_SOURCE_DIR) + "/share/kfd-icp-slam/sick-180-5hz.ini";
const std::string kIntel = std::string(KFD_DATASETS_DIR) + "/intel/intel.rawlog";

// The bundled office log decoded to a plain rawlog (a gzip file is checked whole before any
// object is read, so only a plain file can fail in the middle of the run).
std::string plainOffice() {
    mrpt::io::CFileGZInputStream in(kOffice);
    std::string out, buf(1 << 16, '\0');
    while (const std::size_t n = in.Read(buf.data(), buf.size())) out.append(buf.data(), n);
    return out;
}

// The first line of a refused gzip input: the file, the reason, the hint.
void expectGzipRefusal(const std::string& first, const std::string& app, const std::string& in,
                       const std::string& reason) {
    EXPECT_EQ(first.rfind(app + ": " + in + ": ", 0), 0u) << first;
    EXPECT_NE(first.find(reason), std::string::npos) << first;
    EXPECT_NE(first.find("(truncated or corrupt file?)"), std::string::npos) << first;
}

// --- output paths ----------------------------------------------------------------------------

TEST(BadInputOutputPaths, FilterStatsOnTheInputRawlogIsRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    const Result r = run(KFD_FILTER_EXE, {"-i", in, "-o", d / "out.rawlog", "--stats", in}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-filter: the stats file " + in + " is the input log " + in +
                             ": refusing to overwrite an input");
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, FilterOutputOrStatsOnTheConfigIsRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const auto cfg = d.copy(kIni, "kfd.ini");
    const Snapshot snap({in, cfg});
    Result r = run(KFD_FILTER_EXE, {"-i", in, "-c", cfg, "-o", cfg}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-filter: the output " + cfg + " is the configuration " + cfg +
                             ": refusing to overwrite an input");
    r = run(KFD_FILTER_EXE, {"-i", in, "-c", cfg, "-o", d / "out.rawlog", "--stats", cfg}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-filter: the stats file " + cfg + " is the configuration " + cfg +
                             ": refusing to overwrite an input");
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"in.rawlog", "kfd.ini"}));
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, FilterOutputThroughASymlinkOrHardLinkToTheInputIsRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    fs::create_symlink(in, d / "sym.rawlog");
    fs::create_hard_link(in, d / "hard.rawlog");
    fs::create_directory(d / "sub");
    const Snapshot snap({in});
    for (const std::string& out : {d / "sym.rawlog", d / "hard.rawlog", d / "sub/../in.rawlog"}) {
        const Result r = run(KFD_FILTER_EXE, {"-i", in, "-o", out}, d.path);
        EXPECT_EQ(r.status, 1) << out;
        EXPECT_EQ(r.first(), "kfd-filter: the output " + out + " is the input log " + in +
                                 ": refusing to overwrite an input");
    }
    // The symlink's target counts too, as a stats file.
    const Result r = run(KFD_FILTER_EXE,
                         {"-i", in, "-o", d / "out.rawlog", "--stats", d / "sym.rawlog"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(listing(d.path),
              (std::set<std::string>{"in.rawlog", "sym.rawlog", "hard.rawlog", "sub"}));
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, FilterOutputAndStatsOnTheSameFileAreRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    const std::string out = d / "out.rawlog";
    const Result r = run(KFD_FILTER_EXE, {"-i", in, "-o", out, "--stats", out}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-filter: the stats file " + out + " is also the output " + out);
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, FilterFailureLeavesNoStatsFileAndNoTemporary) {
    Dir d;  // a plain log cut inside an object (its objects are all the same size, so not at
            // half): the run fails after writing rows
    const std::string data = plainOffice();
    const auto in = d.write("cut.rawlog", data.substr(0, data.size() / 2 + 100));
    const Snapshot snap({in});
    const Result r = run(KFD_FILTER_EXE,
                         {"-q", "-i", in, "-o", d / "out.rawlog", "--stats", d / "s.csv"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first().rfind("kfd-filter: cannot read object #", 0), 0u) << r.err;
    EXPECT_EQ(listing(d.path), std::set<std::string>{"cut.rawlog"});
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, IcpSlamChecksEveryInputBeforeTheRun) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const auto cfg = d.copy(kSlamIni, "slam.ini");
    const Snapshot snap({in, cfg});
    const auto t0 = std::chrono::steady_clock::now();
    Result r = run(KFD_ICP_SLAM_EXE, {cfg, in, "-o", d / "out", "--gt", d / "missing.tum"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-icp-slam: ground-truth trajectory not found: " + (d / "missing.tum"));
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
    r = run(KFD_ICP_SLAM_EXE, {cfg, in, "-o", d / "out", "-r", d / "missing.relations"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-icp-slam: relations file not found: " + (d / "missing.relations"));
    // -g takes either format: a missing file is a missing ground truth.
    r = run(KFD_ICP_SLAM_EXE, {cfg, in, "-o", d / "out", "-g", d / "missing.relations"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-icp-slam: ground truth not found: " + (d / "missing.relations"));
    const auto bad_gt = d.write("bad.tum", "1 2 three\n");
    r = run(KFD_ICP_SLAM_EXE, {cfg, in, "-o", d / "out", "--gt", bad_gt}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.first().find("bad.tum"), std::string::npos) << r.err;
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"in.rawlog", "slam.ini", "bad.tum"}));
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, IcpSlamOutputFolderHoldingAnInputIsRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const auto cfg = d.copy(kSlamIni, "slam.ini");
    fs::create_directory(d / "out");
    const auto gt = d.copy(std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.gt.tum",
                           "out/trajectory.tum");
    const Snapshot snap({in, cfg, gt});
    Result r = run(KFD_ICP_SLAM_EXE, {cfg, in, "-o", d / "out", "--gt", gt}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-icp-slam: the output trajectory.tum " + (d / "out/trajectory.tum") +
                             " is the ground-truth trajectory " + gt +
                             ": refusing to overwrite an input");
    r = run(KFD_ICP_SLAM_EXE, {cfg, in, "-o", in}, d.path);  // the rawlog as the output folder
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-icp-slam: the output folder " + in + " is the rawlog " + in);
    EXPECT_EQ(listing(d.path),
              (std::set<std::string>{"in.rawlog", "slam.ini", "out", "out/trajectory.tum"}));
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, IcpSlamFailureKeepsTheFolderAndItsOtherFiles) {
    Dir d;
    const std::string data = plainOffice();
    const auto in = d.write("cut.rawlog", data.substr(0, data.size() / 2 + 100));
    const auto cfg = d.copy(kSlamIni, "slam.ini");
    fs::create_directory(d / "out");
    const auto mine = d.write("out/notes.txt", "mine\n");
    const auto old = d.write("out/summary.json", "{}\n");  // an earlier run's file
    const Snapshot snap({in, cfg, mine, old});
    const Result r = run(KFD_ICP_SLAM_EXE, {"-q", cfg, in, "-o", d / "out", "-m", "none"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first().rfind("kfd-icp-slam: cannot read object #", 0), 0u) << r.err;
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"cut.rawlog", "slam.ini", "out",
                                                      "out/notes.txt", "out/summary.json"}));
    // A new output folder is not created at all.
    const Result r2 = run(KFD_ICP_SLAM_EXE, {"-q", cfg, in, "-o", d / "new", "-m", "none"}, d.path);
    EXPECT_EQ(r2.status, 1);
    EXPECT_FALSE(fs::exists(d / "new"));
    EXPECT_EQ(listing(d.path).size(), 5u);
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, SimulateOutputOnItsRouteIsRefused) {
    Dir d;
    const auto route = d.write("r.gt.tum", "0 0\n5 0\n");
    const auto grid = d.write("g.gridmap", "not a gridmap");
    const Snapshot snap({route, grid});
    const Result r =
        run(KFD_SIMULATE_EXE, {"--gridmap", grid, "--route", route, "-o", d / "r.rawlog"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-simulate: the ground truth " + (d / "r.gt.tum") + " is the route " +
                             route + ": refusing to overwrite an input");
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"r.gt.tum", "g.gridmap"}));
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, ChartAndRenderOutputOnTheirInputIsRefused) {
    Dir d;
    const auto csv = d.write("bars.csv", "group,series,value\na,x,1\n");
    const Snapshot snap({csv});
    Result r = run(KFD_CHART_EXE, {csv, "-o", csv}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-chart: the output image " + csv + " is the input CSV " + csv +
                             ": refusing to overwrite an input");
    r = run(KFD_CHART_EXE, {csv, "-o", d / "bars.png"}, d.path);  // and the good case
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"bars.csv", "bars.png"}));
    snap.expectUnchanged();
#ifdef KFD_RENDER_EXE
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap2({in});
    r = run(KFD_RENDER_EXE, {"-i", in, "--index", "3", "-o", in}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-render: the output image " + in + " is the input log " + in +
                             ": refusing to overwrite an input");
    snap2.expectUnchanged();
#endif
}

// Waits until a temporary output (".*kfd-tmp-*") appears in `dir` or the process ended.
bool waitForTemporary(pid_t pid, const fs::path& dir) {
    for (int i = 0; i < 3000; ++i) {
        for (const auto& name : listing(dir))
            if (name.find("kfd-tmp-") != std::string::npos) return true;
        int ws = 0;
        if (waitpid(pid, &ws, WNOHANG) == pid) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
}

TEST(BadInputOutputPaths, SigintDuringFilterLeavesNothing) {
    if (!fs::exists(kIntel)) GTEST_SKIP() << "missing " << kIntel;
    Dir d;
    const Snapshot snap({kIntel});
    const pid_t pid = spawn(
        KFD_FILTER_EXE,
        {"-i", kIntel, "-o", d / "out.rawlog", "--stats", d / "s.csv", "--compress", "9"}, d.path);
    ASSERT_TRUE(waitForTemporary(pid, d.path)) << "the run ended before it could be interrupted";
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    kill(pid, SIGINT);
    const Result r = finish(pid, d.path);
    EXPECT_EQ(r.status, 130) << r.err;
    EXPECT_NE(r.err.find("kfd-filter: interrupted by signal 2; no output written"),
              std::string::npos)
        << r.err;
    EXPECT_TRUE(listing(d.path).empty());
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, SigtermDuringIcpSlamLeavesNothing) {
    if (!fs::exists(kIntel)) GTEST_SKIP() << "missing " << kIntel;
    Dir d;
    const auto cfg = d.copy(kSlamIni, "slam.ini");
    const Snapshot snap({kIntel, cfg});
    const pid_t pid = spawn(KFD_ICP_SLAM_EXE, {"-q", cfg, kIntel, "-o", d / "out"}, d.path);
    ASSERT_TRUE(waitForTemporary(pid, d.path)) << "the run ended before it could be interrupted";
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    kill(pid, SIGTERM);
    const Result r = finish(pid, d.path);
    EXPECT_EQ(r.status, 128 + SIGTERM) << r.err;
    EXPECT_EQ(r.first(), "kfd-icp-slam: interrupted by signal 15; no output written");
    EXPECT_EQ(listing(d.path), std::set<std::string>{"slam.ini"});
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, SigintDuringSimulateLeavesNoneOfItsFourOutputs) {
    Dir d;
    const pid_t pid = spawn(KFD_SIMULATE_EXE, {"-o", d / "sim.rawlog", "-d", "600"}, d.path);
    ASSERT_TRUE(waitForTemporary(pid, d.path)) << "the run ended before it could be interrupted";
    kill(pid, SIGINT);
    const Result r = finish(pid, d.path);
    EXPECT_EQ(r.status, 130) << r.err;
    EXPECT_NE(r.err.find("kfd-simulate: interrupted by signal 2; no output written"),
              std::string::npos)
        << r.err;
    EXPECT_TRUE(listing(d.path).empty());
}

// --- outputs that are not regular files, SIGHUP, a killed run's temporaries (issue 21) --------

TEST(BadInputOutputPaths, DevicesFifosAndFoldersAreRefusedAsOutputs) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const auto csv = d.write("bars.csv", "group,series,value\na,x,1\n");
    ASSERT_EQ(mkfifo((d / "fifo").c_str(), 0600), 0);
    fs::create_symlink("/dev/null", d / "null.rawlog");  // never the real /dev/null itself
    fs::create_directory(d / "sub");
    // A fresh character device (1, 3: what /dev/null is) when this user may make one.
    const bool chr = mknod((d / "chr").c_str(), S_IFCHR | 0600, makedev(1, 3)) == 0;
    const auto before = listing(d.path);
    const Snapshot snap({in, csv});
    const std::string fifo = d / "fifo", null = d / "null.rawlog", sub = d / "sub";
    auto refused = [&](const std::string& exe, const std::vector<std::string>& args,
                       const std::string& first) {
        const Result r = run(exe, args, d.path);
        EXPECT_EQ(r.status, 1) << r.err;
        EXPECT_EQ(r.first(), first);
    };
    const std::string tail = ", not a regular file: refusing to replace it";
    refused(KFD_FILTER_EXE, {"-q", "-i", in, "-o", fifo},
            "kfd-filter: the output " + fifo + " is a FIFO" + tail);
    refused(KFD_FILTER_EXE, {"-q", "-i", in, "-o", null},
            "kfd-filter: the output " + null + " is a character device" + tail);
    refused(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / "out.rawlog", "--stats", fifo},
            "kfd-filter: the stats file " + fifo + " is a FIFO" + tail);
    refused(KFD_FILTER_EXE, {"-q", "-i", in, "-o", sub},
            "kfd-filter: the output " + sub + " is a folder" + tail);
    if (chr)
        refused(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / "chr"},
                "kfd-filter: the output " + (d / "chr") + " is a character device" + tail);
    refused(KFD_SIMULATE_EXE, {"-q", "-o", fifo, "-d", "1"},
            "kfd-simulate: the output rawlog " + fifo + " is a FIFO" + tail);
    refused(KFD_INJECT_EXE, {"-q", "-i", in, "-o", null},
            "kfd-inject: the output rawlog " + null + " is a character device" + tail);
    refused(KFD_CHART_EXE, {csv, "-o", fifo},
            "kfd-chart: the output image " + fifo + " is a FIFO" + tail);
    refused(KFD_ICP_SLAM_EXE, {"-q", kSlamIni, in, "-o", fifo},
            "kfd-icp-slam: the output folder " + fifo + " is not a folder");
#ifdef KFD_RENDER_EXE
    refused(KFD_RENDER_EXE, {"-i", in, "--index", "3", "-o", null},
            "kfd-render: the output image " + null + " is a character device" + tail);
#endif
    // Nothing written, nothing replaced: the FIFO, the link and the device are what they were.
    EXPECT_EQ(listing(d.path), before);
    EXPECT_TRUE(fs::is_fifo(fs::symlink_status(d / "fifo")));
    EXPECT_TRUE(fs::is_symlink(d / "null.rawlog"));
    EXPECT_EQ(fs::read_symlink(d / "null.rawlog"), "/dev/null");
    if (chr) {
        EXPECT_TRUE(fs::is_character_file(fs::symlink_status(d / "chr")));
    }
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
    snap.expectUnchanged();
}

TEST(BadInputOutputPaths, SighupDuringSimulateLeavesNothing) {
    Dir d;
    const pid_t pid = spawn(KFD_SIMULATE_EXE, {"-o", d / "sim.rawlog", "-d", "600"}, d.path);
    ASSERT_TRUE(waitForTemporary(pid, d.path)) << "the run ended before it could be interrupted";
    kill(pid, SIGHUP);
    const Result r = finish(pid, d.path);
    EXPECT_EQ(r.status, 128 + SIGHUP) << r.err;
    EXPECT_NE(r.err.find("kfd-simulate: interrupted by signal 1; no output written"),
              std::string::npos)
        << r.err;
    EXPECT_TRUE(listing(d.path).empty());
}

// The temporaries (".NAME.kfd-tmp-N.EXT") in `dir`.
std::set<std::string> temporaries(const fs::path& dir) {
    std::set<std::string> t;
    for (const auto& n : listing(dir))
        if (n.find("kfd-tmp-") != std::string::npos) t.insert(n);
    return t;
}

// Polls until `n` temporaries are in `dir` (or the process ended).
bool waitForTemporaries(pid_t pid, const fs::path& dir, std::size_t n) {
    for (int i = 0; i < 3000; ++i) {
        if (temporaries(dir).size() >= n) return true;
        int ws = 0;
        if (waitpid(pid, &ws, WNOHANG) == pid) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
}

TEST(BadInputOutputPaths, TemporariesOfAKilledRunAreRemovedByTheNextRun) {
    Dir d;
    const std::set<std::string> outputs{"sim.rawlog", "sim.gt.tum", "sim.odom.tum",
                                        "sim.labels.csv"};
    // SIGKILL cannot be caught: the four temporaries remain.
    pid_t pid = spawn(KFD_SIMULATE_EXE, {"-q", "-o", d / "sim.rawlog", "-d", "600"}, d.path);
    ASSERT_TRUE(waitForTemporaries(pid, d.path, 4)) << "the run ended too early";
    kill(pid, SIGKILL);
    Result r = finish(pid, d.path);
    EXPECT_EQ(r.status, 128 + SIGKILL);
    EXPECT_EQ(temporaries(d.path).size(), 4u);
    // The next run on the same output removes them (no live process holds them).
    r = run(KFD_SIMULATE_EXE, {"-q", "-o", d / "sim.rawlog", "-d", "1"}, d.path);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(listing(d.path), outputs);
    // A live run's temporaries are left alone by another run on the same output.
    pid = spawn(KFD_SIMULATE_EXE, {"-q", "-o", d / "sim.rawlog", "-d", "600"}, d.path);
    ASSERT_TRUE(waitForTemporaries(pid, d.path, 4)) << "the run ended too early";
    const auto live = temporaries(d.path);
    r = run(KFD_SIMULATE_EXE, {"-q", "-o", d / "sim.rawlog", "-d", "1"}, d.path);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(temporaries(d.path), live);
    kill(pid, SIGINT);
    r = finish(pid, d.path);
    EXPECT_EQ(r.status, 130) << r.err;
    EXPECT_EQ(listing(d.path), outputs);
}

// --- a full file system (issue 21) -----------------------------------------------------------

std::string writeBag(const Dir& d, const std::string& name, int scans = 40);  // below

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

TEST(BadInputFullDisk, FilterRawlogAndStatsFile) {
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

TEST(BadInputFullDisk, FilterWhoseLastBytesDoNotFit) {
    // The issue's case: everything fits but the end of the gzip stream, written when the output
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

TEST(BadInputFullDisk, FilterBagOutput) {
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

TEST(BadInputFullDisk, FilterCarmenOutput) {
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

TEST(BadInputFullDisk, IcpSlamOutputFolder) {
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

TEST(BadInputFullDisk, IcpSlamThreeDScenes) {
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

TEST(BadInputFullDisk, SimulateAndInject) {
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

TEST(BadInputFullDisk, ChartAndRenderImages) {
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

// --- truncated input -------------------------------------------------------------------------

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

TEST(BadInputTruncated, GzipWithoutItsTrailerIsAnError) {
    const std::string data = fileBytes(kOffice);
    expectFilterRefuses(data.substr(0, data.size() - 8), "the gzip stream ends early");
}

TEST(BadInputTruncated, GzipWithAWrongCrcIsAnError) {
    std::string data = fileBytes(kOffice);
    data[data.size() - 8] = static_cast<char>(data[data.size() - 8] ^ 0x01);
    expectFilterRefuses(data, "incorrect data check");
}

TEST(BadInputTruncated, GzipWithAWrongLengthIsAnError) {
    std::string data = fileBytes(kOffice);
    data[data.size() - 1] = static_cast<char>(data[data.size() - 1] ^ 0x01);
    expectFilterRefuses(data, "incorrect length check");
}

TEST(BadInputTruncated, GarbageAfterTheGzipStreamIsAnError) {
    expectFilterRefuses(fileBytes(kOffice) + "garbage", "garbage after the gzip stream");
}

TEST(BadInputTruncated, ACorruptLengthFieldIsAnErrorNotGigabytes) {
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

TEST(BadInputTruncated, IcpSlamOnATruncatedGzipFailsWithNoOutput) {
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

TEST(BadInputTruncated, DenoiseEvalAndRenderOnATruncatedLogFail) {
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

TEST(BadInputTruncated, SimulateOnAGridmapWithoutItsGzipTrailerFails) {
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
TEST(BadInputInject, OutputOnTheInputOrAnUnknownModelIsRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    Result r = run(KFD_INJECT_EXE, {"-q", "-i", in, "-o", in}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(), "kfd-inject: the output rawlog " + in + " is the input rawlog " + in +
                             ": refusing to overwrite an input");
    r = run(KFD_INJECT_EXE, {"-q", "-i", in, "-o", d / "n.rawlog", "--model", "spike"}, d.path);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.first().find("--model"), std::string::npos) << r.err;
    EXPECT_NE(r.first().find("unknown model 'spike'"), std::string::npos) << r.err;
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    // kfd-denoise-eval on labels with a model it does not know: the file and line named.
    const auto labels = d.write("l.csv", "scan,timestamp,beam,kind,model\n0,1.0,3,isolated,nope\n");
    const auto cfg = d.copy(kIni, "kfd.ini");
    r = run(KFD_DENOISE_EVAL_EXE, {"-i", in, "-l", labels, "-c", cfg}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first(),
              "kfd-denoise-eval: " + labels + ":2: unknown noise model 'nope' in labels");
    snap.expectUnchanged();
}

// --- configuration ---------------------------------------------------------------------------

// kfd-filter with a bad configuration: exit 1, the first line, nothing written, inputs kept.
void expectConfigRefused(const std::string& name, const std::string& text,
                         const std::string& message) {
    SCOPED_TRACE(name);
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const auto cfg = d.write(name, text);
    const Snapshot snap({in, cfg});
    const Result r =
        run(KFD_FILTER_EXE,
            {"-q", "-i", in, "-c", cfg, "-o", d / "out.rawlog", "--stats", d / "s.csv"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.first().rfind("kfd-filter: ", 0), 0u) << r.err;
    EXPECT_NE(r.first().find(message), std::string::npos) << r.err;
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"in.rawlog", name}));
    snap.expectUnchanged();
}

TEST(BadInputConfiguration, DuplicateKeysEmptyPipelinesAndHangingYamlAreErrors) {
    expectConfigRefused("dup.ini", "[KFD]\nwindow = 3\nwindow = 4\n", "window");
    expectConfigRefused("dup.yaml", "window: 3\nwindow: 4\n", "window");
    expectConfigRefused("empty.ini", "[KFD]\npipeline =\n", "pipeline");
    expectConfigRefused("range.ini", "[KFD]\nwindow = 0\n", "window");
    // The 4 bytes that made MRPT's YAML parser (libfyaml) loop forever: refused at once.
    expectConfigRefused("hang.yaml",
                        fileBytes(std::string(KFD_SOURCE_DIR) + "/test/data/yaml-hang-4byte.yaml"),
                        "hang.yaml");
}

// --- ROS bags and CARMEN logs (issue 13) ----------------------------------------------------

// A small bag: `scans` scans (40) of a 6 m x 4 m room with odometry, uncompressed.
std::string writeBag(const Dir& d, const std::string& name, int scans) {
    const std::string p = d / name;
    kfd::test::BagBuilder b(p);
    for (int i = 0; i < scans; ++i) {
        b.odom("/odom", 1 + 0.2 * i, 0.05 * i, 0, 0);
        std::vector<float> r(181);
        for (std::size_t k = 0; k < r.size(); ++k) r[k] = 2.0f + 0.01f * static_cast<float>(k % 7);
        b.scan("/scan", kfd::test::BagBuilder::scanMsg(1 + 0.2 * i + 0.1, r));
    }
    return p;
}

// kfd-filter (and kfd-icp-slam) on a bad log: exit 1, the first line names the file and says
// `what`, nothing written, the input unchanged.
void expectLogRefused(const Dir& d, const std::string& in, const std::vector<std::string>& extra,
                      const std::string& what, const std::string& out = "out.bag") {
    SCOPED_TRACE(in + " " + what);
    const auto before = listing(d.path);
    const Snapshot snap({in});
    std::vector<std::string> args{"-q", "-i", in, "-o", d / out, "--stats", d / "s.csv"};
    args.insert(args.end(), extra.begin(), extra.end());
    Result r = run(KFD_FILTER_EXE, args, d.path);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.first().rfind("kfd-filter: ", 0), 0u) << r.err;
    EXPECT_NE(r.first().find(in), std::string::npos) << r.err;
    EXPECT_NE(r.first().find(what), std::string::npos) << r.err;
    args = {kSlamIni, in, "-o", d / "slam", "-q", "--no-map"};
    args.insert(args.end(), extra.begin(), extra.end());
    r = run(KFD_ICP_SLAM_EXE, args, d.path);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.first().find(what), std::string::npos) << r.err;
    EXPECT_EQ(listing(d.path), before);
    snap.expectUnchanged();
}

TEST(BadInputLogs, TruncatedOrCorruptBagsAreRefused) {
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
TEST(BadInputLogs, AChunkThatDoesNotDecompressIsRefusedWhenRead) {
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
TEST(BadInputLogs, AFilteredBagIsCompressedLikeItsInput) {
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

TEST(BadInputLogs, MissingTopicsAndUnsupportedTypesAreRefused) {
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

TEST(BadInputLogs, CarmenLinesWithTheWrongFieldCountAreRefused) {
    Dir d;
    const auto clf =
        d.write("x.clf", "FLASER 2 1 2 0 0 0 0 0 0 5.0 h 0\nFLASER 3 1 2 0 0 0 0 0 0 6.0 h 0\n");
    expectLogRefused(d, clf, {}, clf + ":2: FLASER with 3 readings has 13 fields, expected 14",
                     "out.rawlog");
    const auto num = d.write("y.log", "ODOM 1 2 x 0 0 0 5.0 h 0\n");
    expectLogRefused(d, num, {}, ":1: ODOM field 3 ('x') is not a number", "out.rawlog");
}

TEST(BadInputLogs, ABagOutputNeedsABagInput) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    const Result r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / "out.bag"}, d.path);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.first().find("a bag output (" + (d / "out.bag") + ") needs a ROS bag input"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(listing(d.path), std::set<std::string>{"in.rawlog"});
    snap.expectUnchanged();
}

// Issue 23: an output is written in the format its name says, or refused. Before, any name
// but .bag got an MRPT rawlog (`-o y.clf` and `-o y.txt`: a rawlog, exit 0).
TEST(BadInputLogs, AnOutputNameOfNoFormatKfdWritesIsRefused) {
    Dir d;
    const auto in = d.copy(kOffice, "in.rawlog");
    const Snapshot snap({in});
    for (const std::string name : {"y.txt", "y", "y.clf.txt"}) {
        const Result r = run(KFD_FILTER_EXE, {"-q", "-i", in, "-o", d / name}, d.path);
        EXPECT_EQ(r.status, 1) << name;
        EXPECT_EQ(r.first(), "kfd-filter: the output " + (d / name) +
                                 ": kfd-filter writes .rawlog (an MRPT rawlog), .bag (a ROS 1 "
                                 "bag, for a bag input), .clf or .log (a CARMEN log; .clf.gz, "
                                 ".log.gz: gzip); its name says none of them")
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

TEST(BadInputLogs, AClfOrLogOutputIsACarmenLog) {
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

// --- corrupt length fields (issue 21) ---------------------------------------------------------

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

TEST(BadInputCorruptLength, BagScanRangesLengthIsAnErrorNotGigabytes) {
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

TEST(BadInputCorruptLength, BagWithFlippedMessageBytesIsAnErrorNotGigabytes) {
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

TEST(BadInputCorruptLength, RawlogScanBeamCountIsAnErrorNotGigabytes) {
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

TEST(BadInputCorruptLength, FuzzFindingsAreClearErrors) {
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

TEST(BadInputCorruptLength, CarmenReadingCountIsAnErrorNotGigabytes) {
    Dir d;
    const auto in = d.write("in.clf",
                            "ODOM 0 0 0 0 0 0 1.0 h 0\n"
                            "FLASER 1073741824 1 2 0 0 0 0 0 0 5.0 h 0\n");
    expectCorruptLengthRefused(
        d, in, in + ":2: FLASER reading count 1073741824 is more than the 11 fields after it",
        "out.rawlog");
}

// --- every bad input a clear error or a counted repair (issue 21, item 4) ---------------------

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

TEST(BadInputIssue21, ANonFiniteLaserMountIsAnErrorNamingTheFrame) {
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

TEST(BadInputIssue21, CarmenBinaryGarbageIsCountedAndRefusedWhereItDominates) {
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

TEST(BadInputIssue21, ARunWithNoUsableScanFailsAndWritesNothing) {
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

TEST(BadInputIssue21, LaserScanAnglesStampsAndOdometryAreCountedRepairs) {
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
TEST(BadInputIssue21, RenderChecksTheScanThroughTheDoor) {
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

TEST(BadInputIssue21, AnMrptExceptionSaysWhatIsWrongOnItsFirstLine) {
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
