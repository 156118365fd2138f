// Output-path safety (kfd/os/output_paths.h) and cooperative cancellation (kfd/os/cancel.h).
#include "kfd/os/output_paths.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <type_traits>

#include "kfd/os/cancel.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;

struct TempDir : kfd::test::TempDir {
    TempDir() : kfd::test::TempDir("kfd_paths_") {}
    void touch(const std::string& name, const std::string& text = "x") const {
        std::ofstream(path / name) << text;
    }
};

std::set<std::string> listing(const fs::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::recursive_directory_iterator(dir))
        names.insert(e.path().lexically_relative(dir).string());  // symlinks by name
    return names;
}

TEST(OutputPaths, SameFileThroughEveryKindOfAlias) {
    TempDir d;
    d.touch("in");
    fs::create_symlink(d / "in", d / "sym");
    fs::create_hard_link(d / "in", d / "hard");
    fs::create_directory(d / "sub");
    EXPECT_TRUE(kfd::samePath(d / "in", d / "in"));
    EXPECT_TRUE(kfd::samePath(d / "sym", d / "in"));
    EXPECT_TRUE(kfd::samePath(d / "hard", d / "in"));
    EXPECT_TRUE(kfd::samePath(d / "sub/../in", d / "in"));
    EXPECT_TRUE(kfd::samePath(d / "new", d / "sub/../new"));  // neither exists yet
    EXPECT_FALSE(kfd::samePath(d / "in", d / "new"));
    EXPECT_FALSE(kfd::samePath(d / "in", ""));
    d.touch("other");
    EXPECT_FALSE(kfd::samePath(d / "in", d / "other"));
}

TEST(OutputPaths, CheckNamesBothPathsAndTheirRoles) {
    TempDir d;
    d.touch("in.rawlog");
    const std::string in = d / "in.rawlog", out = d / "out.rawlog";
    EXPECT_NO_THROW(kfd::checkOutputPaths({{"input rawlog", in}, {"configuration", ""}},
                                          {{"output rawlog", out}, {"stats file", ""}}));
    try {
        kfd::checkOutputPaths({{"input rawlog", in}}, {{"output rawlog", out}, {"stats file", in}});
        ADD_FAILURE() << "no error";
    } catch (const kfd::PathError& e) {
        EXPECT_EQ(std::string(e.what()), "the stats file " + in + " is the input rawlog " + in +
                                             ": refusing to overwrite an input");
        EXPECT_EQ(e.field(), in);
    }
    try {
        kfd::checkOutputPaths({}, {{"output rawlog", out}, {"stats file", out}});
        ADD_FAILURE() << "no error";
    } catch (const kfd::PathError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "the stats file " + out + " is also the output rawlog " + out);
    }
    static_assert(std::is_base_of_v<kfd::Error, kfd::PathError>);
}

TEST(OutputPaths, TempFileIsRemovedUnlessCommitted) {
    TempDir d;
    d.touch("keep.png", "old");
    {
        kfd::TempOutputFile t(d / "keep.png");
        EXPECT_EQ(t.path().parent_path(), d.path);
        EXPECT_EQ(t.path().extension(), ".png");  // writers that choose the format by it
        std::ofstream(t.path()) << "partial";
    }
    EXPECT_EQ(listing(d.path), std::set<std::string>{"keep.png"});
    EXPECT_EQ(kfd::test::fileBytes(d / "keep.png"), "old");
    {
        kfd::TempOutputFile t(d / "keep.png");
        std::ofstream(t.path()) << "new";
        t.commit();
    }
    EXPECT_EQ(listing(d.path), std::set<std::string>{"keep.png"});
    EXPECT_EQ(kfd::test::fileBytes(d / "keep.png"), "new");
}

TEST(OutputPaths, TempFileCreatesAMissingParentFolder) {
    TempDir d;
    {
        kfd::TempOutputFile t(d / "out/figs/a.png");  // "-o out/a.png" in a fresh clone
        EXPECT_EQ(t.path().parent_path(), fs::path(d / "out/figs"));
        std::ofstream(t.path()) << "png";
        t.commit();
    }
    EXPECT_EQ(kfd::test::fileBytes(d / "out/figs/a.png"), "png");
    d.touch("file", "x");  // a parent that is a file: an error naming the output
    try {
        kfd::TempOutputFile t(d / "file/a.png");
        ADD_FAILURE() << "no error";
    } catch (const kfd::WriteError& e) {
        EXPECT_NE(std::string(e.what()).find("cannot write " + d / "file/a.png"), std::string::npos)
            << e.what();
    }
}

TEST(OutputPaths, StagedNewFolderAppearsWholeOrNotAtAll) {
    TempDir d;
    {
        kfd::StagedOutputFolder s(d / "a/out");  // the parent is created, the folder staged
        std::ofstream(s.path() / "f.txt") << "1";
        EXPECT_FALSE(fs::exists(d / "a/out"));
    }
    EXPECT_EQ(listing(d.path), std::set<std::string>{"a"});
    {
        kfd::StagedOutputFolder s(d / "a/out");
        std::ofstream(s.path() / "f.txt") << "1";
        s.commit();
    }
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"a", "a/out", "a/out/f.txt"}));
}

TEST(OutputPaths, StagedExistingFolderKeepsItsOtherFiles) {
    TempDir d;
    fs::create_directory(d / "out");
    d.touch("out/mine.txt", "mine");
    d.touch("out/f.txt", "old");
    {
        kfd::StagedOutputFolder s(d / "out");
        std::ofstream(s.path() / "f.txt") << "partial";
    }
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"out", "out/mine.txt", "out/f.txt"}));
    EXPECT_EQ(kfd::test::fileBytes(d / "out/f.txt"), "old");
    {
        kfd::StagedOutputFolder s(d / "out");
        std::ofstream(s.path() / "f.txt") << "new";
        s.commit();
    }
    EXPECT_EQ(listing(d.path), (std::set<std::string>{"out", "out/mine.txt", "out/f.txt"}));
    EXPECT_EQ(kfd::test::fileBytes(d / "out/f.txt"), "new");
    EXPECT_EQ(kfd::test::fileBytes(d / "out/mine.txt"), "mine");
    d.touch("file");
    EXPECT_THROW(kfd::StagedOutputFolder(d / "file"), kfd::PathError);
}

TEST(OutputPaths, OutputsThatAreNotRegularFilesAreRefused) {
    TempDir d;
    ASSERT_EQ(mkfifo((d / "fifo").c_str(), 0600), 0);
    fs::create_symlink("/dev/null", d / "null.rawlog");
    fs::create_directory(d / "sub");
    auto message = [](const kfd::NamedPath& o) -> std::string {
        try {
            kfd::checkOutputPaths({}, {o});
        } catch (const kfd::PathError& e) {
            EXPECT_EQ(e.field(), o.path);
            return e.what();
        }
        return "accepted";
    };
    const std::string fifo = d / "fifo", null = d / "null.rawlog", sub = d / "sub";
    EXPECT_EQ(
        message({"output rawlog", fifo}),
        "the output rawlog " + fifo + " is a FIFO, not a regular file: refusing to replace it");
    EXPECT_EQ(message({"stats file", null}), "the stats file " + null +
                                                 " is a character device, not a regular file: "
                                                 "refusing to replace it");
    EXPECT_EQ(message({"output", sub}),
              "the output " + sub + " is a folder, not a regular file: refusing to replace it");
    EXPECT_EQ(message({"output", d / "new.rawlog"}), "accepted");
    d.touch("old.rawlog");
    EXPECT_EQ(message({"output", d / "old.rawlog"}), "accepted");
    fs::create_symlink(d / "missing", d / "dangling");  // replaced by the rename, as before
    EXPECT_EQ(message({"output", d / "dangling"}), "accepted");
    // The temporary-file owner refuses them too, before creating anything.
    EXPECT_THROW(kfd::TempOutputFile{d / "fifo"}, kfd::PathError);
    EXPECT_THROW(kfd::TempOutputFile{d / "null.rawlog"}, kfd::PathError);
    EXPECT_EQ(listing(d.path),
              (std::set<std::string>{"fifo", "null.rawlog", "sub", "old.rawlog", "dangling"}));
    EXPECT_TRUE(fs::is_fifo(d / "fifo"));
    EXPECT_TRUE(fs::is_character_file("/dev/null"));
}

// Writes `bytes` through an OutputFile on /dev/full (every write fails with ENOSPC) and returns
// the error's message.
std::string writeToFullDevice(std::size_t bytes) {
    try {
        kfd::OutputFile f("/dev/full", "/x/out.rawlog");
        f.write(std::string(bytes, 'x'));
        f.close();
    } catch (const kfd::WriteError& e) {
        EXPECT_EQ(e.field(), "/x/out.rawlog");
        return e.what();
    }
    return "no error";
}

TEST(OutputPaths, OutputFileNamesTheFileAndTheReason) {
    if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
    const std::string expected = "cannot write /x/out.rawlog: No space left on device";
    EXPECT_EQ(writeToFullDevice(10), expected);      // at close (the last flush)
    EXPECT_EQ(writeToFullDevice(200000), expected);  // during the writes
    static_assert(std::is_base_of_v<kfd::PathError, kfd::WriteError>);
}

TEST(OutputPaths, OutputFileWritesAndChecksWhatItWrote) {
    TempDir d;
    std::string text;
    for (int i = 0; i < 20000; ++i) text += std::to_string(i) + "\n";  // > one buffer
    {
        kfd::OutputFile f(d / "a.txt", "a.txt");
        f << "head\n";
        f.write(text);
        f << "tail\n";
        EXPECT_EQ(f.size(), text.size() + 10);
        f.close();
        EXPECT_FALSE(f.isOpen());
        f.close();  // idempotent
    }
    EXPECT_EQ(kfd::test::fileBytes(d / "a.txt"), "head\n" + text + "tail\n");
    try {
        kfd::OutputFile f(d / "missing/a.txt", "final/a.txt");
        ADD_FAILURE() << "no error";
    } catch (const kfd::WriteError& e) {
        EXPECT_EQ(std::string(e.what()), "cannot write final/a.txt: No such file or directory");
    }
}

TEST(OutputPaths, CommitChecksTheFileAndMovesNothingWhenItIsEmpty) {
    TempDir d;
    d.touch("out.rawlog", "old");
    {
        kfd::TempOutputFile t(d / "out.rawlog");
        EXPECT_TRUE(fs::exists(t.path()));  // created at once (exclusively)
        try {
            t.commit();
            ADD_FAILURE() << "an empty output was committed";
        } catch (const kfd::WriteError& e) {
            EXPECT_EQ(std::string(e.what()),
                      "cannot write " + (d / "out.rawlog") + ": the written file is empty");
        }
    }
    EXPECT_EQ(listing(d.path), std::set<std::string>{"out.rawlog"});
    EXPECT_EQ(kfd::test::fileBytes(d / "out.rawlog"), "old");
    {  // a staged folder checks each of its files the same way
        kfd::StagedOutputFolder s(d / "run");
        std::ofstream(s.path() / "full.txt") << "1";
        std::ofstream(s.path() / "empty.txt").close();
        EXPECT_EQ(s.finalName("x.txt"), d / "run/x.txt");
        EXPECT_THROW(s.commit(), kfd::WriteError);
    }
    EXPECT_EQ(listing(d.path), std::set<std::string>{"out.rawlog"});
}

// The names in `dir` that are temporaries (".NAME.kfd-tmp-N...").
std::set<std::string> temporaries(const fs::path& dir) {
    std::set<std::string> t;
    for (const auto& n : listing(dir))
        if (n.find("kfd-tmp-") != std::string::npos) t.insert(n);
    return t;
}

TEST(OutputPaths, TemporariesOfADeadProcessAreRemovedThoseOfALiveOneKept) {
    TempDir d;
    fs::create_directory(d / "old");
    d.touch("old/mine.txt", "mine");
    d.touch(".out.kfd-tmp-12ab.rawlog", "not one of ours");  // not a temporary's name
    d.touch(".other.kfd-tmp-5.rawlog", "another output's");
    // A run killed without unwinding (as by SIGKILL): a file, a new and an existing folder.
    const pid_t pid = fork();
    if (pid == 0) {
        auto* t = new kfd::TempOutputFile(d / "out.rawlog");
        std::ofstream(t->path()) << "partial";
        auto* s = new kfd::StagedOutputFolder(d / "new");
        std::ofstream(s->path() / "f.txt") << "partial";
        auto* e = new kfd::StagedOutputFolder(d / "old");
        std::ofstream(e->path() / "f.txt") << "partial";
        _exit(0);  // no destructor runs; the kernel drops the locks
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    // 2 names that are not temporaries of "out.rawlog", 3 temporaries and 2 files in them.
    ASSERT_EQ(temporaries(d.path).size(), 7u);
    // A live owner's temporary is kept.
    kfd::TempOutputFile live(d / "out.rawlog");
    EXPECT_EQ(temporaries(d.path).size(), 7u);  // the dead one's file went, the live one came
    EXPECT_EQ(kfd::removeStaleTemporaries(d / "out.rawlog"), 0u);
    EXPECT_TRUE(fs::exists(live.path()));
    {
        kfd::StagedOutputFolder s(d / "new");       // the dead run's stage beside it goes
        kfd::StagedOutputFolder e(d / "old");       // and the one inside it
        EXPECT_EQ(temporaries(d.path).size(), 5u);  // the dead stages went, two live ones came
    }
    EXPECT_EQ(temporaries(d.path),
              (std::set<std::string>{live.path().filename().string(), ".out.kfd-tmp-12ab.rawlog",
                                     ".other.kfd-tmp-5.rawlog"}));
    EXPECT_EQ(kfd::test::fileBytes(d / "old/mine.txt"), "mine");
}

TEST(Cancel, RequestIsSeenAndCleared) {
    kfd::resetCancel();
    EXPECT_NO_THROW(kfd::throwIfCancelled());
    kfd::requestCancel(2);
    EXPECT_EQ(kfd::cancelRequested(), 2);
    try {
        kfd::throwIfCancelled();
        ADD_FAILURE() << "no throw";
    } catch (const kfd::Cancelled& e) {
        EXPECT_EQ(e.signal(), 2);
        EXPECT_EQ(std::string(e.what()), "interrupted by signal 2; no output written");
    }
    kfd::resetCancel();
    EXPECT_EQ(kfd::cancelRequested(), 0);
}

}  // namespace
