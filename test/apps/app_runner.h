// Shared by the bad-input tests (test/apps/bad_*_test.cpp): run a built app on a bad input,
// snapshot files, hand-made folders. Each test asserts the exit status, the first line of the
// message, that no output (and no temporary file) was left and that every input is unchanged.
#pragma once

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

#include "kfd/io/open_source.h"
#include "sanitizer.h"
#include "test_bags.h"
#include "test_files.h"

namespace kfd::test::apps {

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
using kfd::test::kAsan;

// Starts `exe args...` with stdout and stderr into files under `dir`; returns the pid. A
// non-zero `address_space` limits the app's address space to that many bytes (RLIMIT_AS; not
// under AddressSanitizer).
inline pid_t spawn(const std::string& exe, const std::vector<std::string>& args,
                   const fs::path& dir, rlim_t address_space = 0) {
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

inline Result finish(pid_t pid, const fs::path& dir) {
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
inline Result run(const std::string& exe, const std::vector<std::string>& args, const fs::path& dir,
                  rlim_t address_space = 0) {
    return finish(spawn(exe, args, dir, address_space), dir);
}

// Every file and folder under `dir` (relative paths), hidden ones included.
inline std::set<std::string> listing(const fs::path& dir) {
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

inline const std::string kOffice = std::string(KFD_SOURCE_DIR) + "/rawlogs/office-mit-0.752.rawlog";
inline const std::string kIni = std::string(KFD_SHARE_DIR) + "/default.ini";
inline const std::string kSlamIni =
    std::string(KFD_SOURCE_DIR) + "/share/kfd-icp-slam/sick-180-5hz.ini";
inline const std::string kIntel = std::string(KFD_DATASETS_DIR) + "/intel/intel.rawlog";

// The bundled office log decoded to a plain rawlog (a gzip file is checked whole before any
// object is read, so only a plain file can fail in the middle of the run).
inline std::string plainOffice() {
    mrpt::io::CFileGZInputStream in(kOffice);
    std::string out, buf(1 << 16, '\0');
    while (const std::size_t n = in.Read(buf.data(), buf.size())) out.append(buf.data(), n);
    return out;
}

// The first line of a refused gzip input: the file, the reason, the hint.
inline void expectGzipRefusal(const std::string& first, const std::string& app,
                              const std::string& in, const std::string& reason) {
    EXPECT_EQ(first.rfind(app + ": " + in + ": ", 0), 0u) << first;
    EXPECT_NE(first.find(reason), std::string::npos) << first;
    EXPECT_NE(first.find("(truncated or corrupt file?)"), std::string::npos) << first;
}

// A small bag: `scans` scans (40) of a 6 m x 4 m room with odometry, uncompressed.
inline std::string writeBag(const Dir& d, const std::string& name, int scans = 40) {
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
inline void expectLogRefused(const Dir& d, const std::string& in,
                             const std::vector<std::string>& extra, const std::string& what,
                             const std::string& out = "out.bag") {
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

}  // namespace kfd::test::apps
