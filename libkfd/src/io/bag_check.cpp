// checkBagStructure (kfd/io/bag_source.h): a walk over a ROS bag 2.0 file's records before
// rosbag_storage reads it. rosbag_storage trusts the file's lengths and offsets (an index entry
// that points outside its chunk makes it read out of bounds), so every length, offset and
// chunk is checked here first. Format: http://wiki.ros.org/Bags/Format/2.0
#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "bag_file.h"
#include "kfd/io/bag_source.h"

namespace kfd {
namespace {

constexpr std::uint8_t kMessageData = 0x02, kBagHeader = 0x03, kIndexData = 0x04, kChunk = 0x05,
                       kChunkInfo = 0x06, kConnection = 0x07;
constexpr std::uint64_t kMaxHeader = 1u << 20;   // a record header is a few fields
constexpr std::uint64_t kMaxChunk = 1ull << 31;  // rosbag's chunks are ~768 KiB

std::uint32_t u32(const unsigned char* p) {
    return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
           std::uint32_t(p[3]) << 24;
}
std::uint64_t u64(const unsigned char* p) { return u32(p) | std::uint64_t(u32(p + 4)) << 32; }

struct Header {
    std::map<std::string, std::string> fields;
    bool has(const char* k) const { return fields.count(k) > 0; }
};

enum class Inflated { Ok, Corrupt, OtherSize };

// The output buffer of a chunk's decompression grows with what the data really holds, up to
// the announced size and one byte more (to tell a larger content): a corrupt size field costs
// no memory, where allocating the announced size first made an 18 kB bag take 2.1 GB.
class GrowingOutput {
  public:
    GrowingOutput(std::vector<unsigned char>& out, std::uint64_t size, std::size_t compressed)
        : out_(out), limit_(size + 1) {
        out_.resize(static_cast<std::size_t>(
            std::min<std::uint64_t>(limit_, std::max<std::uint64_t>(1u << 20, 8 * compressed))));
    }
    /// Room for at least `want` bytes after the `used` ones, when the limit allows.
    bool grow(std::size_t used, std::size_t want) {
        if (room(used) >= want) return true;
        if (out_.size() < limit_)
            out_.resize(static_cast<std::size_t>(std::min<std::uint64_t>(
                limit_, std::max<std::uint64_t>(2 * out_.size(), used + want))));
        return room(used) >= want;
    }
    unsigned char* at(std::size_t used) { return out_.data() + used; }
    // At most 1 GiB at a time: the libraries count in int.
    std::size_t room(std::size_t used) const {
        return std::min<std::size_t>(out_.size() - used, 1u << 30);
    }
    Inflated finish(std::size_t used, std::uint64_t size) {
        out_.resize(used);
        return used == size ? Inflated::Ok : Inflated::OtherSize;
    }

  private:
    std::vector<unsigned char>& out_;
    std::uint64_t limit_;
};

Inflated inflateBz2(std::vector<unsigned char>& in, std::uint64_t size,
                    std::vector<unsigned char>& out) {
    GrowingOutput buf(out, size, in.size());
    bz_stream s{};
    if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) return Inflated::Corrupt;
    s.next_in = reinterpret_cast<char*>(in.data());
    s.avail_in = static_cast<unsigned int>(in.size());
    std::size_t used = 0;
    Inflated r = Inflated::Ok;
    for (;;) {
        if (!buf.grow(used, 1)) {
            r = Inflated::OtherSize;  // more than announced
            break;
        }
        const std::size_t room = buf.room(used);
        s.next_out = reinterpret_cast<char*>(buf.at(used));
        s.avail_out = static_cast<unsigned int>(room);
        const int rc = BZ2_bzDecompress(&s);
        used += room - s.avail_out;
        if (rc == BZ_STREAM_END) break;
        if (rc != BZ_OK || (s.avail_in == 0 && s.avail_out > 0)) {  // corrupt, or cut short
            r = Inflated::Corrupt;
            break;
        }
    }
    BZ2_bzDecompressEnd(&s);
    return r == Inflated::Ok ? buf.finish(used, size) : r;
}

Inflated inflateLz4(std::vector<unsigned char>& in, std::uint64_t size,
                    std::vector<unsigned char>& out) {
    // roslz4 decompresses a block whole into the output, or says the output is too small
    // (ROSLZ4_OUTPUT_SMALL, its state kept for a retry); blocks are at most 4 MiB.
    constexpr std::size_t kMaxBlock = 4u << 20;
    GrowingOutput buf(out, size, in.size());
    roslz4_stream s{};
    s.input_next = reinterpret_cast<char*>(in.data());
    s.input_left = static_cast<int>(in.size());
    if (roslz4_decompressStart(&s) != ROSLZ4_OK) return Inflated::Corrupt;
    std::size_t used = 0;
    Inflated r = Inflated::Ok;
    for (;;) {
        if (s.input_left == 0) {
            r = Inflated::Corrupt;  // cut short: no end of stream
            break;
        }
        buf.grow(used, kMaxBlock);
        const std::size_t room = buf.room(used);
        s.output_next = reinterpret_cast<char*>(buf.at(used));
        s.output_left = static_cast<int>(room);
        const int rc = roslz4_decompress(&s);
        used += room - static_cast<std::size_t>(s.output_left);
        if (rc == ROSLZ4_STREAM_END) {
            if (s.input_left != 0) r = Inflated::Corrupt;  // bytes after the stream
            break;
        }
        if (rc == ROSLZ4_OUTPUT_SMALL && !buf.grow(used, kMaxBlock)) {
            // At the limit: a block larger than what is left of the announced size, or
            // corrupt data (roslz4 cannot tell them apart below a block's room).
            r = Inflated::OtherSize;
            break;
        }
        if (rc < 0 && rc != ROSLZ4_OUTPUT_SMALL) {
            r = Inflated::Corrupt;
            break;
        }
    }
    roslz4_decompressEnd(&s);
    return r == Inflated::Ok ? buf.finish(used, size) : r;
}

}  // namespace

const ChunkMessage* Chunk::find(std::uint32_t offset) const {
    const auto it =
        std::lower_bound(messages.begin(), messages.end(), offset,
                         [](const ChunkMessage& m, std::uint32_t o) { return m.offset < o; });
    return it != messages.end() && it->offset == offset ? &*it : nullptr;
}

struct BagFile::Impl {
    explicit Impl(const std::string& path)
        : path_(path), file_(std::fopen(path.c_str(), "rb"), &std::fclose) {
        if (!file_) fail(0, "cannot open the file");
        std::error_code ec;
        size_ = std::filesystem::file_size(path_, ec);
        if (ec) fail(0, "cannot tell the file's size");
    }

    void run(bool chunks) {
        decompress_ = chunks;
        unsigned char magic[13];
        if (!readAt(0, magic, 13) || std::memcmp(magic, "#ROSBAG V2.0\n", 13) != 0)
            fail(0, "not a ROS bag 2.0 (no '#ROSBAG V2.0' line)");
        std::uint64_t pos = 13;
        bool seen_header = false;
        while (pos < size_) {
            const std::uint64_t at = pos;
            Header h;
            std::vector<unsigned char> data;
            std::uint64_t dlen = 0;
            pos = record(pos, h, data, dlen);
            const std::uint8_t op = opOf(h, at);
            if (!seen_header) {
                if (op != kBagHeader) fail(at, "the first record is not the bag header");
                seen_header = true;
                index_pos_ = u64field(h, "index_pos", at);
                chunk_count_ = u32field(h, "chunk_count", at);
                if (index_pos_ == 0)
                    fail(at,
                         "the bag has no index (cut short while recording? `rosbag reindex` "
                         "repairs it)");
                if (index_pos_ > size_)
                    fail(at, "the index lies beyond the end of the file (truncated?)");
                continue;
            }
            switch (op) {
                case kChunk:
                    chunk(h, data, dlen, at);
                    break;
                case kIndexData:
                    indexData(h, data, at);
                    break;
                case kConnection:
                    (void)u32field(h, "conn", at);
                    connectionHeader(data.data(), data.size(), at);
                    break;
                case kChunkInfo:
                    chunkInfo(h, at);
                    break;
                default:
                    fail(at, "unexpected record (op " + std::to_string(op) + ")");
            }
        }
        if (!seen_header) fail(13, "the bag has no header record");
        if (chunks_.size() < chunk_count_)
            fail(size_, "the bag header announces " + std::to_string(chunk_count_) +
                            " chunks, the file holds " + std::to_string(chunks_.size()) +
                            " (truncated?)");
        if (infos_ < chunks_.size())
            fail(size_, "the index lists " + std::to_string(infos_) + " of the " +
                            std::to_string(chunks_.size()) + " chunks (truncated?)");
    }

    void readChunk(std::uint64_t pos, Chunk& out) {
        Header h;
        std::vector<unsigned char> data;
        std::uint64_t dlen = 0;
        const bool was = decompress_;
        decompress_ = true;  // record() reads the chunk's data
        record(pos, h, data, dlen);
        decompress_ = was;
        if (opOf(h, pos) != kChunk) fail(pos, "the index points to a record that is not a chunk");
        inflate(h, data, pos, out);
        ++loaded_;
    }

    [[noreturn]] void fail(std::uint64_t at, const std::string& what) const {
        throw BagFileError(path_ + ": byte " + std::to_string(at) + ": " + what, path_);
    }

    std::size_t chunks() const { return chunks_.size(); }
    std::string compression() const {
        std::string best = "none";
        std::size_t most = 0;
        for (const auto& [c, n] : compressions_)
            if (n > most) best = c, most = n;
        return best;
    }
    std::size_t loaded() const { return loaded_; }

  private:
    bool readAt(std::uint64_t at, void* buf, std::size_t n) {
        if (at + n > size_) return false;
        if (std::fseek(file_.get(), static_cast<long>(at), SEEK_SET) != 0) return false;
        return std::fread(buf, 1, n, file_.get()) == n;
    }

    // Parses the header fields of `bytes` (len bytes).
    Header parseHeader(const unsigned char* bytes, std::uint64_t len, std::uint64_t at) const {
        Header h;
        std::uint64_t p = 0;
        while (p < len) {
            if (len - p < 4) fail(at, "a header field is cut short");
            const std::uint32_t flen = u32(bytes + p);
            p += 4;
            if (flen > len - p) fail(at, "a header field is longer than its header");
            const std::string field(reinterpret_cast<const char*>(bytes + p), flen);
            p += flen;
            const auto eq = field.find('=');
            if (eq == std::string::npos) fail(at, "a header field without '='");
            h.fields[field.substr(0, eq)] = field.substr(eq + 1);
        }
        return h;
    }

    // Reads the record at `pos` (header parsed, data read when this check reads it, its length
    // in `dlen`); returns the position after it.
    std::uint64_t record(std::uint64_t pos, Header& h, std::vector<unsigned char>& data,
                         std::uint64_t& dlen) {
        unsigned char len[4];
        if (!readAt(pos, len, 4)) fail(pos, "a record is cut short (truncated file?)");
        const std::uint64_t hlen = u32(len);
        if (hlen > kMaxHeader || pos + 4 + hlen + 4 > size_)
            fail(pos, "a record header runs past the end of the file (truncated?)");
        std::vector<unsigned char> hb(hlen);
        if (!readAt(pos + 4, hb.data(), hlen) || !readAt(pos + 4 + hlen, len, 4))
            fail(pos, "read error");
        h = parseHeader(hb.data(), hlen, pos);
        dlen = u32(len);
        const std::uint64_t dpos = pos + 8 + hlen;
        const std::uint8_t op = opOf(h, pos);
        // Index data: rosbag_storage reads its count entries of 12 bytes and goes on from
        // there, whatever the length field says (bags of 2010 announce 20 bytes an entry).
        if (op == kIndexData) {
            const std::uint64_t entries = 12ull * u32field(h, "count", pos);
            if (entries > dlen) fail(pos, "index data shorter than its entries");
            dlen = entries;
        }
        if (dlen > size_ - dpos)
            fail(pos, "a record's data runs past the end of the file (truncated?)");
        // The data this check reads (a chunk's only when it decompresses it).
        if ((op == kChunk && decompress_) || op == kIndexData || op == kConnection) {
            data.resize(dlen);
            if (dlen && !readAt(dpos, data.data(), dlen)) fail(pos, "read error");
        }
        return dpos + dlen;
    }

    // A connection record's data is itself a header (topic, type, md5sum, definition) that
    // rosbag_storage parses with ros::Header::parse, which copies a field before checking that
    // it fits (a fuzzed length read past the buffer: test/fuzz/corpus/bag/finding-*).
    void connectionHeader(const unsigned char* bytes, std::uint64_t len, std::uint64_t at) const {
        if (len > kMaxHeader) fail(at, "a connection header of more than 1 MiB");
        (void)parseHeader(bytes, len, at);
    }

    std::uint8_t opOf(const Header& h, std::uint64_t at) const {
        const auto it = h.fields.find("op");
        if (it == h.fields.end() || it->second.size() != 1) fail(at, "a record without an op");
        return static_cast<std::uint8_t>(it->second[0]);
    }
    std::uint32_t u32field(const Header& h, const char* k, std::uint64_t at) const {
        const auto it = h.fields.find(k);
        if (it == h.fields.end() || it->second.size() != 4)
            fail(at, std::string("a record without a 4-byte '") + k + "' field");
        return u32(reinterpret_cast<const unsigned char*>(it->second.data()));
    }
    std::uint64_t u64field(const Header& h, const char* k, std::uint64_t at) const {
        const auto it = h.fields.find(k);
        if (it == h.fields.end() || it->second.size() != 8)
            fail(at, std::string("a record without an 8-byte '") + k + "' field");
        return u64(reinterpret_cast<const unsigned char*>(it->second.data()));
    }

    // A chunk's compression and announced size (what a chunk record's header must say).
    std::pair<std::string, std::uint64_t> chunkHeader(const Header& h, std::uint64_t at) const {
        const auto c = h.fields.find("compression");
        if (c == h.fields.end()) fail(at, "a chunk without 'compression'");
        const std::uint64_t size = u32field(h, "size", at);
        if (size > kMaxChunk) fail(at, "a chunk of more than 2 GiB");
        if (c->second != "none" && c->second != "bz2" && c->second != "lz4")
            fail(at, "a chunk with unknown compression '" + c->second + "'");
        return {c->second, size};
    }

    // Decompresses the chunk record at `at` (header h, data) into `out` and checks its records:
    // connections and messages, each within the chunk.
    void inflate(const Header& h, std::vector<unsigned char>& data, std::uint64_t at, Chunk& out) {
        const auto [compression, size] = chunkHeader(h, at);
        std::vector<unsigned char>& plain = out.plain;
        out.messages.clear();
        if (compression == "none") {
            if (data.size() != size) fail(at, "a chunk's size field does not match its data");
            plain.swap(data);
        } else {
            const Inflated r = compression == "bz2" ? inflateBz2(data, size, plain)
                                                    : inflateLz4(data, size, plain);
            if (r == Inflated::Corrupt)
                fail(at, "a " + compression + " chunk does not decompress (corrupt)");
            if (r == Inflated::OtherSize)
                fail(at, "a chunk decompresses to another size than announced");
        }
        std::uint64_t p = 0;
        while (p < plain.size()) {
            if (plain.size() - p < 4) fail(at, "a record inside a chunk is cut short (corrupt)");
            const std::uint64_t hlen = u32(plain.data() + p);
            if (hlen > plain.size() - p - 4 || plain.size() - p - 4 - hlen < 4)
                fail(at, "a record inside a chunk runs past the chunk (corrupt)");
            const Header rh = parseHeader(plain.data() + p + 4, hlen, at);
            const std::uint64_t dlen = u32(plain.data() + p + 4 + hlen);
            if (dlen > plain.size() - p - 8 - hlen)
                fail(at, "a message inside a chunk runs past the chunk (corrupt)");
            const std::uint8_t op = opOf(rh, at);
            if (op != kMessageData && op != kConnection)
                fail(at, "a chunk holds a record of op " + std::to_string(op));
            (void)u32field(rh, "conn", at);
            if (op == kConnection) connectionHeader(plain.data() + p + 8 + hlen, dlen, at);
            if (op == kMessageData)
                out.messages.push_back(ChunkMessage{static_cast<std::uint32_t>(p),
                                                    static_cast<std::uint32_t>(p + 8 + hlen),
                                                    static_cast<std::uint32_t>(dlen)});
            p += 8 + hlen + dlen;
        }
    }

    void chunk(const Header& h, std::vector<unsigned char>& data, std::uint64_t dlen,
               std::uint64_t at) {
        const auto [compression, size] = chunkHeader(h, at);
        ++compressions_[compression];
        last_starts_.clear();
        if (decompress_) {
            Chunk c;
            inflate(h, data, at, c);
            for (const ChunkMessage& m : c.messages) last_starts_.insert(m.offset);
        } else if (compression == "none" && dlen != size) {
            fail(at, "a chunk's size field does not match its data");
        }
        chunks_.push_back(at);
    }

    void indexData(const Header& h, const std::vector<unsigned char>& data, std::uint64_t at) {
        if (chunks_.empty()) fail(at, "index data before any chunk");
        const std::uint64_t count = u32field(h, "count", at);
        if (data.size() != count * 12) fail(at, "index data of the wrong length");
        if (!decompress_) return;  // the entries' offsets: checked when the chunk is read
        for (std::uint64_t i = 0; i < count; ++i)
            if (!last_starts_.count(u32(data.data() + 12 * i + 8)))
                fail(at, "an index entry points to no message of its chunk (corrupt)");
    }

    void chunkInfo(const Header& h, std::uint64_t at) {
        const std::uint64_t pos = u64field(h, "chunk_pos", at);
        bool found = false;
        for (const auto c : chunks_) found = found || c == pos;
        if (!found) fail(at, "the index points to a chunk that is not there (corrupt)");
        ++infos_;
    }

    std::string path_;
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_;
    bool decompress_ = true;
    std::uint64_t size_ = 0, index_pos_ = 0, chunk_count_ = 0;
    std::vector<std::uint64_t> chunks_;
    std::map<std::string, std::size_t> compressions_;  // chunks by compression
    std::set<std::uint32_t> last_starts_;
    std::size_t infos_ = 0, loaded_ = 0;
};

BagFile::BagFile(const std::string& path) : impl_(std::make_unique<Impl>(path)) {}
BagFile::~BagFile() = default;
void BagFile::check(bool chunks) { impl_->run(chunks); }
void BagFile::readChunk(std::uint64_t pos, Chunk& out) { impl_->readChunk(pos, out); }
void BagFile::fail(std::uint64_t at, const std::string& what) const { impl_->fail(at, what); }
std::size_t BagFile::chunks() const { return impl_->chunks(); }
std::string BagFile::compression() const { return impl_->compression(); }
std::size_t BagFile::chunksLoaded() const { return impl_->loaded(); }

void checkBagStructure(const std::string& path) { BagFile(path).check(true); }

}  // namespace kfd
