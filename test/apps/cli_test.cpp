// The apps' command-line layer (apps/common/cli.h): number parsing, the exit-code contract and
// the message format, directly and through every built app.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/cli.h"
#include "kfd/algorithms/evidence_filter.h"
#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/pipeline/stage_keys.h"
#include "kfd/stages/core_stages.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;

// --- The layer itself -----------------------------------------------------------------------

template <class T>
std::string numberMessage(const std::string& text) {
    T value{};
    return kfd::app::parseNumber(text, value);
}

TEST(CliNumbers, WholeBaseTenNumbersParse) {
    int i = 0;
    EXPECT_EQ(kfd::app::parseNumber("010", i), "");
    EXPECT_EQ(i, 10);  // not octal
    EXPECT_EQ(kfd::app::parseNumber("+7", i), "");
    EXPECT_EQ(i, 7);
    EXPECT_EQ(kfd::app::parseNumber("-3", i), "");
    EXPECT_EQ(i, -3);
    double d = 0.0;
    EXPECT_EQ(kfd::app::parseNumber("1e-3", d), "");
    EXPECT_DOUBLE_EQ(d, 1e-3);
    EXPECT_EQ(kfd::app::parseNumber("-0.5", d), "");
    EXPECT_DOUBLE_EQ(d, -0.5);
    std::uint32_t u = 0;
    EXPECT_EQ(kfd::app::parseNumber("4000000000", u), "");
    EXPECT_EQ(u, 4000000000u);
}

TEST(CliNumbers, BadTextIsNamedWithWhatWasExpected) {
    EXPECT_EQ(numberMessage<int>("abc"), "'abc' is not an integer");
    EXPECT_EQ(numberMessage<int>("1.5"), "'1.5' is not an integer");
    EXPECT_EQ(numberMessage<int>("0x10"), "'0x10' is not an integer");
    EXPECT_EQ(numberMessage<int>(""), "'' is not an integer");
    EXPECT_EQ(numberMessage<int>(" 1"), "' 1' is not an integer");
    EXPECT_EQ(numberMessage<int>("+-1"), "'+-1' is not an integer");
    EXPECT_EQ(numberMessage<double>("1.5abc"), "'1.5abc' is not a number");  // stod took 1.5
    EXPECT_EQ(numberMessage<double>("1,5"), "'1,5' is not a number");
    EXPECT_EQ(numberMessage<std::uint32_t>("-1"), "'-1' is not a non-negative integer");
    EXPECT_EQ(numberMessage<int>("99999999999"), "'99999999999' is out of range");
    EXPECT_EQ(numberMessage<std::uint32_t>("4294967296"), "'4294967296' is out of range");
    EXPECT_EQ(numberMessage<double>("1e999"), "'1e999' is out of range");
    EXPECT_THROW(kfd::app::toNumber<double>("x"), kfd::app::UsageError);
    EXPECT_EQ(kfd::app::toNumber<long>("42"), 42);
}

TEST(CliNumbers, RangeValidatorNamesTheBounds) {
    auto range = kfd::app::inRange(0, 9);
    std::string text = "9";
    EXPECT_EQ(range(text), "");
    text = "10";
    EXPECT_EQ(range(text), "'10' is outside [0, 9]");
    text = "x";
    EXPECT_EQ(range(text), "'x' is not an integer");
}

/// Runs a Cli over `args` with `body`; returns the exit status, stderr in `err`.
int runCli(kfd::app::Cli& cli, std::vector<std::string> args, const std::function<void()>& body,
           std::string* err) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    testing::internal::CaptureStdout();
    testing::internal::CaptureStderr();
    const int status = cli.run(static_cast<int>(argv.size()), argv.data(), body);
    testing::internal::GetCapturedStdout();
    *err = testing::internal::GetCapturedStderr();
    return status;
}

TEST(Cli, ExitCodesFollowTheContract) {
    std::string err;
    int n = 0;
    bool ran = false;
    auto make = [&](kfd::app::Cli& cli) { cli.option("-n,--number", n, "a number"); };
    {
        kfd::app::Cli cli("app", "[-n N]", "about");
        make(cli);
        EXPECT_EQ(runCli(
                      cli, {"app", "-n", "4"}, [&] { ran = true; }, &err),
                  0);
        EXPECT_TRUE(ran);
        EXPECT_EQ(n, 4);
        EXPECT_EQ(err, "");
    }
    {
        kfd::app::Cli cli("app", "[-n N]", "about");
        make(cli);
        ran = false;
        EXPECT_EQ(runCli(
                      cli, {"app", "-n", "4x"}, [&] { ran = true; }, &err),
                  2);
        EXPECT_FALSE(ran);  // the body never runs on bad usage
        EXPECT_EQ(err, "app: --number: '4x' is not an integer\nTry 'app --help'.\n");
    }
    {
        kfd::app::Cli cli("app", "[-n N]", "about");
        make(cli);
        EXPECT_EQ(runCli(
                      cli, {"app"}, [] { throw kfd::app::UsageError("give -n"); }, &err),
                  2);
        EXPECT_EQ(err, "app: give -n\nTry 'app --help'.\n");
    }
    {
        kfd::app::Cli cli("app", "[-n N]", "about");
        make(cli);
        EXPECT_EQ(runCli(
                      cli, {"app"}, [] { throw kfd::Error("cannot open x", "x"); }, &err),
                  1);
        EXPECT_EQ(err, "app: cannot open x\n");  // bad input: no usage hint
    }
    {
        // An MRPT exception's banner and call stack (nested, as MRPT_END rethrows): the first
        // line says what is wrong, the banner and the stack are left out.
        kfd::app::Cli cli("app", "[-n N]", "about");
        make(cli);
        const std::string banner =
            "==== MRPT exception ====\nMessage:  outer\nLocation: a.cpp:1: [f\nCall stack "
            "backtrace:\n[0 ] x\n==== MRPT exception ====\nMessage:  ASSERT_EQUAL_(a,b) "
            "failed with\na=1\nb=2\n\nLocation: b.cpp:2: [g\nCall stack backtrace:\n[0 ] y\n";
        EXPECT_EQ(runCli(
                      cli, {"app"}, [&] { throw std::logic_error(banner); }, &err),
                  1);
        EXPECT_EQ(err, "app: ASSERT_EQUAL_(a,b) failed with; a=1; b=2\n");
        EXPECT_EQ(kfd::plainMessage("cannot read [KFD]: " + banner),
                  "cannot read [KFD]: ASSERT_EQUAL_(a,b) failed with; a=1; b=2");
        EXPECT_EQ(kfd::plainMessage("two\nlines"), "two\nlines");  // not MRPT's: as it is
    }
    {
        kfd::app::Cli cli("app", "[-n N]", "about");
        make(cli);
        EXPECT_EQ(runCli(
                      cli, {"app", "-n", "1", "-n", "2"}, [] {}, &err),
                  0);
        EXPECT_EQ(n, 2);  // a repeated option keeps its last value, as before
    }
}

TEST(Cli, ProgressIsOneLinePerTenPercentOffATerminalAndOffWithQuiet) {
    kfd::app::ProgressPrinter p("app");
    testing::internal::CaptureStderr();
    for (double f : {0.0, 0.05, 0.12, 0.19, 1.0}) p.update(f, 3, 2);
    p.abort();  // no unfinished line off a terminal
    EXPECT_EQ(testing::internal::GetCapturedStderr(),
              "[app]   0%  3 scans, 2 kept\n[app]  12%  3 scans, 2 kept\n"
              "[app] 100%  3 scans, 2 kept\n");
    kfd::app::Cli cli("app", "", "about");
    cli.addQuiet();
    std::string err;
    ASSERT_EQ(runCli(
                  cli, {"app", "-q"}, [] {}, &err),
              0);
    EXPECT_EQ(cli.progress(), nullptr);
}

// --- Every app ------------------------------------------------------------------------------

struct Result {
    int status = -1;
    std::string out, err;
};

std::string slurp(const fs::path& p) { return kfd::test::fileBytes(p.string()); }

/// Runs `exe args` through the shell, stdout and stderr kept apart.
Result runApp(const std::string& exe, const std::string& args) {
    const fs::path dir = fs::temp_directory_path() / ("kfd_cli_test_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const std::string cmd = "'" + exe + "' " + args + " > '" + (dir / "out").string() + "' 2> '" +
                            (dir / "err").string() + "'";
    const int st = std::system(cmd.c_str());
    Result r{WIFEXITED(st) ? WEXITSTATUS(st) : -1, slurp(dir / "out"), slurp(dir / "err")};
    fs::remove_all(dir);
    return r;
}

struct App {
    const char* name;
    const char* exe;
};

std::vector<App> apps() {
    std::vector<App> a{{"kfd-filter", KFD_FILTER_EXE},
                       {"kfd-icp-slam", KFD_ICP_SLAM_EXE},
                       {"kfd-eval", KFD_EVAL_EXE},
                       {"kfd-simulate", KFD_SIMULATE_EXE},
                       {"kfd-denoise-eval", KFD_DENOISE_EVAL_EXE},
                       {"kfd-chart", KFD_CHART_EXE}};
#ifdef KFD_RENDER_EXE
    a.push_back({"kfd-render", KFD_RENDER_EXE});
#endif
    return a;
}

/// Bad usage: status 2, "APP: message" and "Try 'APP --help'." on stderr, nothing on stdout.
void expectUsageError(const App& app, const std::string& args, const std::string& message) {
    SCOPED_TRACE(std::string(app.name) + " " + args);
    const Result r = runApp(app.exe, args);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err.rfind(std::string(app.name) + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(std::string("\nTry '") + app.name + " --help'.\n"), std::string::npos)
        << r.err;
}

struct UsageCase {
    const char* app;
    const char* args;
    const char* message;  // a part of the message
};

/// Every case through expectUsageError (kfd-render's only where it is built).
void expectUsageErrors(const std::vector<UsageCase>& cases) {
    const auto built = apps();
    for (const auto& c : cases) {
        const auto it = std::find_if(built.begin(), built.end(),
                                     [&](const App& a) { return c.app == std::string(a.name); });
        if (it != built.end())
            expectUsageError(*it, c.args, c.message);
        else
            EXPECT_STREQ(c.app, "kfd-render") << "not built";
    }
}

TEST(CliApps, HelpExitsZeroWithUsageOnStdout) {
    for (const auto& a : apps()) {
        SCOPED_TRACE(a.name);
        for (const char* flag : {"--help", "-h"}) {
            const Result r = runApp(a.exe, flag);
            EXPECT_EQ(r.status, 0);
            EXPECT_EQ(r.out.rfind(std::string("Usage: ") + a.name + " ", 0), 0u) << r.out;
            EXPECT_NE(r.out.find("-h,--help"), std::string::npos) << r.out;
            EXPECT_EQ(r.err, "");
        }
    }
}

TEST(CliApps, UnknownFlagIsBadUsage) {
    for (const auto& a : apps()) expectUsageError(a, "--bogus", "not expected: --bogus");
    expectUsageErrors({
        // Named even when it leaves a required argument out (a typo: "--ouput x").
        {"kfd-simulate", "--ouput x.rawlog", "not expected: --ouput x.rawlog"},
        {"kfd-eval", "est.tum -r gt.relations extra.tum", "not expected: extra.tum"},
    });
}

TEST(CliApps, BadUsageExitsTwoAndSaysWhatIsWrong) {
    expectUsageErrors({
        // A bad number names the flag and the value.
        {"kfd-filter", "-i a -o b --compress abc", "--compress: 'abc' is not an integer"},
        {"kfd-filter", "-i a -o b --compress 12", "--compress: '12' is outside"},
        {"kfd-filter", "--suggest-window 0.4 5x", "--suggest-window: '5x' is not a number"},
        {"kfd-icp-slam", "x.ini --max-dt 1ms", "--max-dt: '1ms' is not a number"},
        {"kfd-icp-slam", "x.ini -m odometry --match-drop ten",
         "--match-drop: 'ten' is not a number"},
        {"kfd-eval", "est.tum -r gt.relations --rpe-delta 1,5",
         "--rpe-delta: '1,5' is not a number"},
        {"kfd-simulate", "-o x.rawlog -v fast", "--speed: 'fast' is not a number"},
        {"kfd-simulate", "-o x.rawlog --seed -1", "--seed: '-1' is not a non-negative integer"},
        {"kfd-chart", "in.csv -o out.png --size 640 wide", "--size: 'wide' is not an integer"},
        {"kfd-render", "-i a -o b.png --index 3rd", "--index: '3rd' is not an integer"},
        {"kfd-render", "-i a -o b.png --index 3 --size big", "--size: 'big' is not an integer"},
        {"kfd-denoise-eval", "-i a -l b -c c --laser-only=maybe", "--laser-only"},
        // A missing required argument.
        {"kfd-filter", "-o out.rawlog", "no input log (-i)"},
        {"kfd-filter", "--list", "--list: no input log (-i)"},
        {"kfd-icp-slam", "", "no configuration (CONFIG.ini)"},
        {"kfd-icp-slam", "--list", "--list: no input log"},
        {"kfd-eval", "-r gt.relations", "EST.tum is required"},
        {"kfd-simulate", "-w office", "--output is required"},
        {"kfd-denoise-eval", "-i a.rawlog -l a.labels.csv", "-c is required"},
        {"kfd-chart", "in.csv", "-o is required"},
        {"kfd-render", "-i a --index 1", "no output image (-o)"},
        // A missing value, or arguments that contradict each other.
        {"kfd-eval", "est.tum -r", "--relations"},
        {"kfd-eval", "est.tum", "give a ground truth: -g FILE (or --relations, --gt)"},
        {"kfd-icp-slam", "x.ini a.rawlog -i b.rawlog", "input log given twice"},
        {"kfd-filter", "-i a.bag -o b.bag --removed-as zero", "--removed-as"},
        {"kfd-filter", "-i a.bag -o b.bag --bag-compression zip", "--bag-compression"},
        {"kfd-icp-slam", "x.ini --match-drop 10",
         "a matched drop rate (--match-drop, --match-drop-of) applies to --mode odometry or "
         "decimate only (not kfd)"},
        {"kfd-icp-slam", "x.ini --mode fast", "--mode: unknown pre-filter mode"},
        {"kfd-simulate", "-o x.rawlog --gridmap g", "--gridmap and --route"},
        {"kfd-chart", "in.csv -o out.png --size 640", "--size"},
        {"kfd-render", "-i a -o b.png", "give exactly one of --index and --time"},
    });
}

TEST(CliApps, BadInputExitsOneWithoutTheUsageHint) {
    const Result r = runApp(KFD_DENOISE_EVAL_EXE, "-i a -l b -c /nonexistent.ini");
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err.rfind("kfd-denoise-eval: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("/nonexistent.ini"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("Try "), std::string::npos) << r.err;
    EXPECT_EQ(runApp(KFD_CHART_EXE, "/nonexistent.csv -o out.png").status, 1);
}

TEST(CliApps, FilterVersionAndEarlyExits) {
    Result r = runApp(KFD_FILTER_EXE, "--version");
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.out.rfind("kfd-filter ", 0), 0u) << r.out;
    r = runApp(KFD_FILTER_EXE, "--suggest-window 0.752 40");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("window = "), std::string::npos) << r.out;
    r = runApp(KFD_FILTER_EXE, "--suggest-window 0.4 5 0.9");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("p_pair = 0.9 "), std::string::npos) << r.out;
    expectUsageErrors({{"kfd-filter", "--suggest-window 0.4 5 2", "--suggest-window: p_pair"}});
    r = runApp(KFD_FILTER_EXE, "--list-keys");
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("min_range"), std::string::npos) << r.out;
    // Each key with its defaults, read here from the Params structs: "key default kfd range
    // meaning" (the kfd column: share/kfd/default.ini, which leaves these keys out).
    const kfd::EvidenceFilter::Params ev;
    const kfd::ViewKeyframeSelector::Params kf;
    for (const auto& [key, value] :
         {std::pair{"incidence_deg", kfd::keys::formatReal(ev.incidence_deg)},
          {"max_removed_fraction", kfd::keys::formatReal(ev.max_removed_fraction)},
          {"max_confirmed_fraction", kfd::keys::formatReal(ev.max_confirmed_fraction)},
          {"temporal_scans", std::to_string(ev.temporal_scans)},
          {"next_scan", std::string(ev.next_scan ? "true" : "false")},
          {"view_samples", std::to_string(kf.view.max_samples)}}) {
        std::istringstream lines(r.out);
        std::string line, name, def, kfd_value;
        while (std::getline(lines, line) && line.rfind(std::string(key) + " ", 0) != 0) {
        }
        std::istringstream(line) >> name >> def >> kfd_value;
        EXPECT_EQ(name, key) << r.out;
        EXPECT_EQ(def, value) << line;
        EXPECT_EQ(kfd_value, value) << line;
    }
    r = runApp(KFD_FILTER_EXE, "--compress 0 --print-config");
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.out.rfind("[KFD]", 0), 0u) << r.out;
}

#ifdef KFD_RENDER_EXE
// next_scan (issue 25) in kfd-render: the drawn scan is denoised with the scan after it as
// evidence; the log's last scan, without one, is drawn too.
TEST(CliApps, RenderDrawsAScanWithNextScanTheLogsLastToo) {
    kfd::test::TempDir d("kfd_cli_");
    std::ofstream(d / "next.ini") << "[KFD]\nnext_scan = true\n";
    const std::string office = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";
    for (const char* pick : {"--index 40", "--time 1e12"}) {
        fs::remove(d / "r.png");
        const Result r = runApp(KFD_RENDER_EXE, "-i '" + office + "' " + pick + " -o '" +
                                                    d / "r.png" + "' -c '" + d / "next.ini" + "'");
        EXPECT_EQ(r.status, 0) << pick << ": " << r.err;
        EXPECT_GT(fs::file_size(d / "r.png"), 1000u) << pick;
        EXPECT_NE(r.out.find("removed as noise"), std::string::npos) << r.out;
    }
}

// One row of kfd-filter's per-scan CSV: index -> "KEPT (reason), P returns, R removed as
// noise", as kfd-render titles the scan.
std::vector<std::string> filterRows(const std::string& csv) {
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);  // index,timestamp,sensor,kept,reason,points_in,removed_noise,...
    std::vector<std::string> rows;
    while (std::getline(in, line)) {
        std::vector<std::string> c;
        std::stringstream cells(line);
        for (std::string cell; std::getline(cells, cell, ',');) c.push_back(cell);
        rows.push_back(std::string(c.at(3) == "1" ? "KEPT" : "DROPPED") + " (" + c.at(4) + "), " +
                       c.at(5) + " returns, " + c.at(6) + " removed as noise");
    }
    return rows;
}

// Issue 37: kfd-render draws exactly what kfd-filter did to a scan (the same history: the
// whole log up to it through the same pipeline), kept or dropped, the most removed too.
TEST(CliApps, RenderShowsKfdFiltersRowForTheSameScan) {
    kfd::test::TempDir d("kfd_cli_");
    std::vector<std::string> logs = {std::string(KFD_SOURCE_DIR) +
                                     "/rawlogs/office-mit-0.752.rawlog"};
    const std::string fr079 = std::string(KFD_DATASETS_DIR) + "/fr079/fr079.rawlog";
    if (fs::exists(fr079)) logs.push_back(fr079);
    for (const std::string& log : logs) {
        const Result f = runApp(KFD_FILTER_EXE, "-q -i '" + log + "' -o '" + d / "o.rawlog" +
                                                    "' --stats '" + d / "s.csv" + "'");
        ASSERT_EQ(f.status, 0) << f.err;
        const auto rows = filterRows(d / "s.csv");
        ASSERT_GT(rows.size(), 100u);
        std::vector<std::size_t> picks;  // the first kept and dropped after 50, the most removed
        std::size_t most = 0, most_removed = 0;
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const std::size_t removed = std::stoul(rows[i].substr(rows[i].rfind(", ") + 2));
            if (removed > most_removed) most = i, most_removed = removed;
        }
        for (const char* kind : {"KEPT", "DROPPED"})
            for (std::size_t i = 50; i < rows.size(); ++i)
                if (rows[i].rfind(kind, 0) == 0) {
                    picks.push_back(i);
                    break;
                }
        picks.push_back(most);
        EXPECT_GT(most_removed, 0u) << log;
        for (std::size_t i : picks) {
            const Result r =
                runApp(KFD_RENDER_EXE, "-i '" + log + "' --index " + std::to_string(i) + " -o '" +
                                           d / "r.png" + "'");
            ASSERT_EQ(r.status, 0) << r.err;
            EXPECT_NE(r.out.find("): " + rows[i] + " ("), std::string::npos)
                << log << " scan " << i << ": kfd-filter's row " << rows[i] << "\n"
                << r.out;
        }
    }
}
#endif

// kfd-compare reads the mode list from here (python/kfd_tools/compare.py): one line a
// mode, "name<TAB>stages<TAB>description", before the required CONFIG.ini is asked for.
TEST(CliApps, IcpSlamListsEveryModeWithItsStages) {
    const Result r = runApp(KFD_ICP_SLAM_EXE, "--list-modes");
    ASSERT_EQ(r.status, 0) << r.err;
    std::vector<std::string> names;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) {
        ASSERT_EQ(std::count(line.begin(), line.end(), '\t'), 2) << line;
        names.push_back(line.substr(0, line.find('\t')));
    }
    EXPECT_EQ(names, (std::vector<std::string>{"none", "odometry", "keyframe", "kfd", "dbscan",
                                               "radius", "sor", "decimate"}));
    EXPECT_NE(r.out.find("none\t-\t"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("odometry\tmotion\t"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("radius\tdistance,radius\t"), std::string::npos) << r.out;
}

}  // namespace
