// Output-path safety shared by every app and library entry point that writes files (std and
// POSIX): no output may be (or alias) an input or another output, nor be anything but a regular
// file; every byte kfd writes goes through one checked writer (OutputFile); every output is
// written under a temporary name in its own folder, synced and checked, and renamed into place
// only when complete.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "kfd/pipeline/error.h"

namespace kfd {

/// An output that equals or aliases an input or another output, that exists and is not a
/// regular file, or a temporary file or folder that cannot be created or moved into place.
/// `field()` is the path at fault.
class PathError : public Error {
  public:
    using Error::Error;
};

/// An output that cannot be written completely: creating it, a write, the final flush, the
/// fsync or the close failed, or the file is not what was written (size, last bytes, empty).
/// The message names the file users know (the final name, never the temporary one) and the
/// operating system's reason: "cannot write out.rawlog: No space left on device". `field()` is
/// that file.
class WriteError : public PathError {
  public:
    using PathError::PathError;
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
/// output is the same file as an input or as another output, or exists and is not a regular
/// file (checkRegularOutput). Empty paths are ignored. Call it before anything is opened for
/// writing.
void checkOutputPaths(const std::vector<NamedPath>& inputs, const std::vector<NamedPath>& outputs);

/// Throws PathError when `output` exists (symlinks followed) and is not a regular file: "the
/// output rawlog /dev/null is a character device, not a regular file: refusing to replace it"
/// (a folder, a character or block device, a FIFO, a socket). Renaming a finished file over it
/// would replace the device node or the FIFO by a regular file. No stdout form exists.
void checkRegularOutput(const NamedPath& output);

/// True when the name of `path` ends in `extension` (".rawlog", ".clf.gz"), letter case aside.
bool hasExtension(const std::string& path, const std::string& extension);

/// Throws PathError when the name of `output` ends in none of `extensions` (hasExtension): "the
/// output rawlog y.txt: " + `formats` + "; its name says none of them", e.g. formats = "kfd-
/// simulate writes an MRPT rawlog (.rawlog)". An output is written in the format its name says.
void checkOutputName(const NamedPath& output, const std::vector<std::string>& extensions,
                     const std::string& formats);

/// The one writer of kfd's output bytes: a file written through its descriptor with every error
/// checked. write() buffers (64 KiB) and throws WriteError when write(2) fails (ENOSPC, EIO,
/// EFBIG...); close() flushes, fsyncs, checks that the file holds exactly the bytes written
/// (fstat's size, and its last 16 bytes read back: a gzip's trailer, a PNG's IEND chunk) and
/// closes, each step checked. Errors name `name`, the file users know. The destructor closes
/// without checks when close() was not called (the caller discards the file).
class OutputFile {
  public:
    /// Creates or truncates `path` for writing (WriteError naming `name` when it cannot).
    OutputFile(const std::filesystem::path& path, std::string name);
    ~OutputFile();
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    void write(const void* data, std::size_t size);
    void write(std::string_view text) { write(text.data(), text.size()); }
    OutputFile& operator<<(std::string_view text) {
        write(text);
        return *this;
    }
    /// Bytes written so far.
    std::uint64_t size() const { return size_; }
    bool isOpen() const { return fd_ >= 0; }
    /// The file users know, for messages.
    const std::string& name() const { return name_; }
    /// Flushes, fsyncs, verifies and closes (WriteError on any failure). Idempotent.
    void close();

  private:
    [[noreturn]] void fail(const std::string& reason);
    void flush();

    int fd_ = -1;
    std::string name_;
    std::string buffer_;
    std::string tail_;  // the last bytes handed to write(2), to read back
    std::uint64_t size_ = 0, flushed_ = 0;
};

/// Checks a finished file someone else wrote (a library that swallows errors): it is a regular
/// file, not empty, and fsync succeeds. WriteError naming `name` otherwise.
void syncAndCheckFile(const std::filesystem::path& path, const std::string& name);

/// A fresh, not yet existing name beside `final_path` in the same folder (so that a rename is
/// atomic): ".STEM.kfd-tmp-NNNNNN.EXT" (hidden; the extension last, for writers that choose
/// the format by it).
std::filesystem::path temporaryPathFor(const std::filesystem::path& final_path);

/// Removes the temporary files and folders of `final_path` (the names temporaryPathFor gives)
/// that a killed run left (SIGKILL, a crash, a power cut): those of this user that no live
/// process holds. Every TempOutputFile and StagedOutputFolder holds an exclusive flock(2) on
/// its temporary until it is renamed or removed; the kernel drops the lock when its process
/// dies, so a temporary that can be locked is stale. On a file system without locks nothing is
/// removed. Returns how many were removed. TempOutputFile and StagedOutputFolder call it.
std::size_t removeStaleTemporaries(const std::filesystem::path& final_path);

/// A file written under a temporary name and moved over its final name by commit(). The
/// temporary is created at once (exclusively, and locked for removeStaleTemporaries); until
/// commit() the destructor removes it (on any failure or cancellation nothing partial
/// remains). Stale temporaries of the same output are removed first. A missing parent folder
/// is created (and remains), as StagedOutputFolder does.
class TempOutputFile {
  public:
    /// PathError when `final_path` exists and is not a regular file; WriteError when the
    /// temporary cannot be created.
    explicit TempOutputFile(std::filesystem::path final_path);
    ~TempOutputFile();
    TempOutputFile(const TempOutputFile&) = delete;
    TempOutputFile& operator=(const TempOutputFile&) = delete;
    /// Where to write now (through OutputFile, or a library that writes the file itself).
    const std::filesystem::path& path() const { return temp_; }
    const std::filesystem::path& finalPath() const { return final_; }
    /// Checks the finished temporary (syncAndCheckFile: regular, not empty, fsync; WriteError
    /// naming the final file) and renames it over the final one (PathError when that fails).
    /// Close its OutputFile first.
    void commit();

  private:
    std::filesystem::path final_, temp_;
    int lock_ = -1;  // the temporary, open and flock'ed until it is renamed or removed
    bool committed_ = false;
};

/// An output folder staged in a temporary folder and moved into place by commit(). A folder
/// that does not exist yet is staged beside it (".NAME.kfd-tmp-NNNNNN") and renamed as a
/// whole; an existing folder is staged inside itself and commit() moves each staged file over
/// the file of the same name, leaving the folder's other files alone. commit() first checks
/// every staged file (syncAndCheckFile: regular, not empty, fsync; WriteError naming its final
/// name). Until commit() the destructor removes the staging folder. Parent folders that had to
/// be created remain. Stale staging folders of the same output are removed first.
class StagedOutputFolder {
  public:
    explicit StagedOutputFolder(std::filesystem::path final_dir);
    ~StagedOutputFolder();
    StagedOutputFolder(const StagedOutputFolder&) = delete;
    StagedOutputFolder& operator=(const StagedOutputFolder&) = delete;
    /// Where to write now.
    const std::filesystem::path& path() const { return staging_; }
    const std::filesystem::path& finalPath() const { return final_; }
    /// The name users know of a file written into the stage: finalPath() / name.
    std::string finalName(const std::string& name) const { return (final_ / name).string(); }
    bool committed() const { return committed_; }
    void commit();

  private:
    std::filesystem::path final_, staging_;
    int lock_ = -1;  // the staging folder, open and flock'ed until moved or removed
    bool committed_ = false;
};

}  // namespace kfd
