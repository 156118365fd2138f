// A ROS bag 2.0 file read by kfd itself, record by record (bag_check.cpp): the structure check
// that runs before rosbag_storage opens a bag (checkBagStructure, kfd/io/bag_source.h), and
// the chunks a BagSource reads, each decompressed and its records checked when it is loaded.
// Private to libkfd. Format: http://wiki.ros.org/Bags/Format/2.0
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "kfd/io/bag_source.h"

namespace kfd {

/// A BagError of the file's structure, its message whole ("PATH: byte N: WHAT"): passed on as it
/// is by the code that names messages.
class BagFileError : public BagError {
  public:
    using BagError::BagError;
};

/// A message data record inside a decompressed chunk.
struct ChunkMessage {
    std::uint32_t offset = 0;  // the record's offset in the chunk (what index entries name)
    std::uint32_t data = 0;    // its data's offset in the chunk
    std::uint32_t size = 0;    // its data's size
};

/// A chunk's records, decompressed: `plain` and its message records, in offset order.
struct Chunk {
    std::vector<unsigned char> plain;
    std::vector<ChunkMessage> messages;
    /// The message record at `offset`, or null when no message record starts there.
    const ChunkMessage* find(std::uint32_t offset) const;
};

/// A bag file open for kfd's own reading; BagError (naming the file and the byte) on anything
/// corrupt, truncated or missing.
class BagFile {
  public:
    /// Opens `path` (BagError when it cannot be opened).
    explicit BagFile(const std::string& path);
    ~BagFile();
    BagFile(const BagFile&) = delete;
    BagFile& operator=(const BagFile&) = delete;

    /// Walks every record of the file (see checkBagStructure). With `chunks` false the chunks'
    /// data is neither read nor decompressed here (only their headers and the index entries'
    /// lengths are checked): readChunk() checks a chunk's records when it loads it.
    void check(bool chunks);
    /// The chunk record at byte `pos`, decompressed (its output growing with what the data
    /// holds, up to the announced size) and its records checked. Counted (chunksLoaded()).
    void readChunk(std::uint64_t pos, Chunk& out);
    /// Throws the BagFileError "PATH: byte AT: WHAT".
    [[noreturn]] void fail(std::uint64_t at, const std::string& what) const;

    /// After check(): the chunks in the file, and the compression of most of them ("none",
    /// "bz2" or "lz4"; "none" for a bag without chunks).
    std::size_t chunks() const;
    std::string compression() const;
    /// Chunks loaded by readChunk() so far.
    std::size_t chunksLoaded() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace kfd
