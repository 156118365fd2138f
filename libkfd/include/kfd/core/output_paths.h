// Output-path safety shared by every app and library entry point that writes files (std only):
// no output may be (or alias) an input or another output, and every output is written under a
// temporary name in its own folder and renamed into place only when complete.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "kfd/core/error.h"

namespace kfd {

/// An output that equals or aliases an input or another output, or a temporary file or folder
/// that cannot be created or moved into place. `field()` is the path at fault.
class PathError : public Error {
  public:
    using Error::Error;
};

/// A path with the role it plays, for messages: {"input rawlog", "in.rawlog"}.
struct NamedPath {
    std::string role;
    std::string path;
};

/// True when `a` and `b` name the same file: std::filesystem::equivalent when both exist (same
/// file, symlink to it, hard link), else equal weakly-canonical absolute paths (a file not yet
/// written, or a dangling symlink compared by its own name).
bool samePath(const std::filesystem::path& a, const std::filesystem::path& b);

/// Throws PathError ("the output rawlog out.rawlog is the input rawlog in.rawlog") when an
/// output is the same file as an input or as another output. Empty paths are ignored. Call it
/// before anything is opened for writing.
void checkOutputPaths(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

/// A fresh, not yet existing name beside `final_path` in the same folder (so that a rename is
/// atomic): ".STEM.kfd-tmp-NNNNNN.EXT" (hidden; the extension last, for writers that choose
/// the format by it).
std::filesystem::path temporaryPathFor(const std::filesystem::path& final_path);

/// A file written under a temporary name and moved over its final name by commit(). Until then
/// the destructor removes the temporary file (on any failure or cancellation nothing partial
/// remains).
class TempOutputFile {
  public:
    explicit TempOutputFile(std::filesystem::path final_path);
    ~TempOutputFile();
    TempOutputFile(const TempOutputFile&) = delete;
    TempOutputFile& operator=(const TempOutputFile&) = delete;
    /// Where to write now.
    const std::filesystem::path& path() const { return temp_; }
    const std::filesystem::path& finalPath() const { return final_; }
    /// Renames the temporary file over the final one (PathError when that fails).
    void commit();

  private:
    std::filesystem::path final_, temp_;
    bool committed_ = false;
};

/// An output folder staged in a temporary folder and moved into place by commit(). A folder
/// that does not exist yet is staged beside it (".NAME.kfd-tmp-NNNNNN") and renamed as a
/// whole; an existing folder is staged inside itself and commit() moves each staged file over
/// the file of the same name, leaving the folder's other files alone. Until commit() the
/// destructor removes the staging folder. Parent folders that had to be created remain.
class StagedOutputFolder {
  public:
    explicit StagedOutputFolder(std::filesystem::path final_dir);
    ~StagedOutputFolder();
    StagedOutputFolder(const StagedOutputFolder&) = delete;
    StagedOutputFolder& operator=(const StagedOutputFolder&) = delete;
    /// Where to write now.
    const std::filesystem::path& path() const { return staging_; }
    const std::filesystem::path& finalPath() const { return final_; }
    bool committed() const { return committed_; }
    void commit();

  private:
    std::filesystem::path final_, staging_;
    bool committed_ = false;
};

}  // namespace kfd
