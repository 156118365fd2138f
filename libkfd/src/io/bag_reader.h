// A bag's messages in rosbag::View's order, read from chunks that kfd loads itself (BagFile):
// each chunk decompressed once while the messages of several chunks interleave, in a cache of
// bounded size. Private to libkfd (the bag source's).
#pragma once

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "bag_file.h"
#include "bag_message.h"

namespace kfd {

/// Why: rosbag_storage keeps one chunk decompressed. Reading a bag through rosbag::View whose
/// messages are held and copied later (a scan waits for the odometry after it) switched between
/// chunks and decompressed them again and again (5.3 s of CPU for a 13 s bz2 bag that
/// decompresses in 1.0 s), and kfd's structure check decompressed every chunk once more.
///
/// The order of the messages is rosbag::View's (its index, read by rosbag_storage: by bag time,
/// ties broken as View does). The bytes come from BagFile::readChunk (decompressed and checked
/// there; an index entry that points to no message record of its chunk is a BagError naming
/// the chunk's byte). Loaded chunks stay in a cache until every message of theirs has been
/// read by the consuming cursor, or the cache holds more than `cache_bytes` (the least recently
/// used then go): memory stays bounded, and a bag whose chunks do not interleave beyond that
/// decompresses each chunk once.
class BagReader {
  public:
    static constexpr std::uint64_t kDefaultCacheBytes = 64ull << 20;

    /// `file` checked (BagFile::check) and `bag` opened on the same file; both outlive this.
    BagReader(BagFile& file, const rosbag::Bag& bag,
              std::uint64_t cache_bytes = kDefaultCacheBytes);
    ~BagReader();
    BagReader(const BagReader&) = delete;
    BagReader& operator=(const BagReader&) = delete;

    /// The messages of one topic, or of all ("") in order. A consuming cursor (one per reader:
    /// the source's pass over the whole bag) frees each chunk once it has read all of its
    /// messages; others (the first messages looked at when a bag is opened) leave the cache to
    /// it.
    class Cursor {
      public:
        ~Cursor();
        Cursor(Cursor&&) noexcept;
        /// The next message into `out`; false at the end.
        bool next(NativeMessage& out);
        /// The messages this cursor goes over.
        std::size_t size() const;

      private:
        friend class BagReader;
        struct Impl;
        explicit Cursor(std::unique_ptr<Impl> impl);
        std::unique_ptr<Impl> impl_;
    };
    Cursor cursor(const std::string& topic = {}, bool consuming = false);

    /// Chunks loaded (decompressed, for compressed ones) so far, and the bag's chunks.
    std::size_t chunksLoaded() const;
    std::size_t chunks() const;

  private:
    struct Cached {
        std::shared_ptr<const Chunk> chunk;
        std::uint64_t used = 0;  // when it was last read (a tick)
    };
    // The chunk at `pos`, from the cache or loaded.
    std::shared_ptr<const Chunk> chunkAt(std::uint64_t pos);
    // One message of the consuming cursor read from the chunk at `pos`.
    void consumed(std::uint64_t pos);

    BagFile& file_;
    const rosbag::Bag& bag_;
    std::uint64_t cache_bytes_, cached_bytes_ = 0, tick_ = 0;
    std::map<std::uint64_t, Cached> cache_;
    std::unordered_map<std::uint64_t, std::size_t> unread_;  // messages left per chunk
};

}  // namespace kfd
