// Output-path safety (kfd/core/output_paths.h) and cooperative cancellation (kfd/core/cancel.h).
#include "kfd/core/output_paths.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <type_traits>

#include "kfd/core/cancel.h"
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
