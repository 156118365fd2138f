// A gzip file written with every error checked (the writing twin of the sources' gzip reader):
// an mrpt::io::CStream that MRPT's serialisation writes into, over kfd's checked OutputFile.
#pragma once

#include <mrpt/io/CStream.h>
#include <mrpt/serialization/CSerializable.h>

#include <exception>
#include <filesystem>
#include <memory>
#include <string>

#include "kfd/os/output_paths.h"

namespace kfd {

/// Writes one gzip member through zlib's deflate, as MRPT's CFileGZOutputStream does (gzip
/// header without name or time, a 32 KiB window, memory level 8, the given level; the
/// decompressed bytes are the same), but into an OutputFile: every write, the end of the
/// stream (its CRC-32 and length trailer), the fsync and the close are checked, and close()
/// reads the trailer back (CFileGZOutputStream ignores the final flush's error: a full disk
/// left a cut-short gzip and no error). Every failure is a WriteError naming the file users know
/// and the reason ("cannot write out.rawlog: No space left on device"), never one of MRPT's
/// stacked exceptions: write(obj) serialises one object and rethrows the stream's own error.
class GzOutputStream : public mrpt::io::CStream {
  public:
    /// Creates `path`; `name` is the file users know (the final name of a temporary); `level`
    /// 0 (stored) .. 9 (smallest); MRPT's default is 1.
    GzOutputStream(const std::filesystem::path& path, std::string name, int level = 1);
    ~GzOutputStream() override;
    GzOutputStream(const GzOutputStream&) = delete;
    GzOutputStream& operator=(const GzOutputStream&) = delete;

    /// Serialises one object (MRPT's CArchive): WriteError when the file cannot take it.
    void write(const mrpt::serialization::CSerializable& obj);
    /// Ends the gzip stream and closes the file, checked (OutputFile::close). Call it before the
    /// temporary file is committed: without it the file has no trailer.
    void close();
    /// The file users know.
    const std::string& name() const;

    // mrpt::io::CStream: a write-only stream (Read and Seek throw WriteError).
    size_t Read(void* buffer, size_t count) override;
    size_t Write(const void* buffer, size_t count) override;
    uint64_t Seek(int64_t offset, TSeekOrigin origin = sFromBeginning) override;
    uint64_t getTotalBytesCount() const override;  // uncompressed bytes written
    uint64_t getPosition() const override;
    std::string getStreamDescription() const override;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace kfd
