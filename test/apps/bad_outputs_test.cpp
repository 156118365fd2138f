// Outputs that are refused (an input, a link to one, a device, a folder) and runs that end early
// (a failure, SIGINT, SIGTERM, SIGHUP, a killed run's temporaries): nothing half-written is left.
#include "app_runner.h"
#include "bad_logs.h"

namespace {

using namespace kfd::test::apps;

// --- output paths ---

TEST(BadOutputs, FilterStatsOnTheInputRawlogIsRefused) {
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

TEST(BadOutputs, FilterOutputOrStatsOnTheConfigIsRefused) {
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

TEST(BadOutputs, FilterOutputThroughASymlinkOrHardLinkToTheInputIsRefused) {
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

TEST(BadOutputs, FilterOutputAndStatsOnTheSameFileAreRefused) {
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

TEST(BadOutputs, FilterFailureLeavesNoStatsFileAndNoTemporary) {
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

TEST(BadOutputs, IcpSlamChecksEveryInputBeforeTheRun) {
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

TEST(BadOutputs, IcpSlamOutputFolderHoldingAnInputIsRefused) {
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

TEST(BadOutputs, IcpSlamFailureKeepsTheFolderAndItsOtherFiles) {
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

TEST(BadOutputs, SimulateOutputOnItsRouteIsRefused) {
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

TEST(BadOutputs, ChartAndRenderOutputOnTheirInputIsRefused) {
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

TEST(InterruptedRuns, SigintDuringFilterLeavesNothing) {
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

TEST(InterruptedRuns, SigtermDuringIcpSlamLeavesNothing) {
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

TEST(InterruptedRuns, SigintDuringSimulateLeavesNoneOfItsFourOutputs) {
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

// --- outputs that are not regular files, SIGHUP, a killed run's temporaries (issue 21) ---

TEST(BadOutputs, DevicesFifosAndFoldersAreRefusedAsOutputs) {
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

TEST(InterruptedRuns, SighupDuringSimulateLeavesNothing) {
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

TEST(InterruptedRuns, TemporariesOfAKilledRunAreRemovedByTheNextRun) {
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

}  // namespace
