// The MRPT rawlog source: both layouts, plain or gzip.
#pragma once

#include <memory>
#include <string>

#include "kfd/io/source.h"

namespace kfd {

/// Bad rawlog input or output: missing or unreadable file, not a rawlog, truncated rawlog, a
/// scan whose laser mount is not finite, write failure.
class RawlogError : public SourceError {
  public:
    using SourceError::SourceError;
};

/// Reads a whole file through the same gzip checks as RawlogSource (trailer CRC-32 and length,
/// a stream cut short, bytes after the last member; a plain file is only read), for inputs that
/// MRPT reads itself (a .gridmap.gz) and that would pass a damaged trailer. Throws RawlogError
/// naming the file and the reason.
void checkGzipIntegrity(const std::string& path);

/// Reads an MRPT rawlog object by object: the "actions + sensory frames" layout
/// (CActionCollection, CSensoryFrame, ...) or the "observations" layout (CObservation...),
/// or a mix, plain or gzip-compressed (zlib reads both). An action immediately followed by a
/// sensory frame forms one Frame entry; a frame without one is a Frame entry with a null
/// action; an action followed by anything else is an Action entry.
///
/// End of file: MRPT's CArchive::ReadObject throws CExceptionEOF when the file ends exactly
/// at an object boundary and a plain std::exception when it ends inside an object. The first
/// ends next() normally, unless zlib reports that the gzip stream itself was cut short (its
/// decoded data happened to end at a boundary); the second is a truncated or corrupt file:
/// RawlogError. A plain file cut exactly at an object boundary is a valid, shorter rawlog.
/// A 2D scan whose sensor pose (the laser mount) is not finite is a RawlogError naming the
/// file, the object and the scan's sensor label, as a bag's or a CARMEN log's mount is.
class RawlogSource : public Source {
  public:
    /// Opens `path`; RawlogError when it is missing, unreadable or empty.
    explicit RawlogSource(const std::string& path);
    ~RawlogSource() override;
    RawlogSource(const RawlogSource&) = delete;
    RawlogSource& operator=(const RawlogSource&) = delete;

    bool next(SourceEntry& e) override;
    const std::string& path() const override;
    std::uint64_t bytesRead() const override;
    std::uint64_t bytesTotal() const override;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace kfd
