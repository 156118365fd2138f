// checkBagStructure (kfd/mrpt/bag_source.h): a walk over a ROS bag 2.0 file's records before
// rosbag_storage reads it. rosbag_storage trusts the file's lengths and offsets (an index entry
// that points outside its chunk makes it read out of bounds), so every length, offset and
// chunk is checked here first. Format: http://wiki.ros.org/Bags/Format/2.0
#include <bzlib.h>
#include <roslz4/lz4s.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "kfd/mrpt/bag_source.h"

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

class Checker {
  public:
    explicit Checker(const std::string& path) : path_(path) {}

    void run() {
        std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path_.c_str(), "rb"),
                                                          &std::fclose);
        if (!f) fail(0, "cannot open the file");
        file_ = f.get();
        std::error_code ec;
        size_ = std::filesystem::file_size(path_, ec);
        if (ec) fail(0, "cannot tell the file's size");
        unsigned char magic[13];
        if (!readAt(0, magic, 13) || std::memcmp(magic, "#ROSBAG V2.0\n", 13) != 0)
            fail(0, "not a ROS bag 2.0 (no '#ROSBAG V2.0' line)");
        std::uint64_t pos = 13;
        bool seen_header = false;
        while (pos < size_) {
            const std::uint64_t at = pos;
            Header h;
            std::vector<unsigned char> data;
            pos = record(pos, h, data);
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
                    chunk(h, data, at);
                    break;
                case kIndexData:
                    indexData(h, data, at);
                    break;
                case kConnection:
                    (void)u32field(h, "conn", at);
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

  private:
    [[noreturn]] void fail(std::uint64_t at, const std::string& what) const {
        throw BagError(path_ + ": byte " + std::to_string(at) + ": " + what, path_);
    }

    bool readAt(std::uint64_t at, void* buf, std::size_t n) {
        if (at + n > size_) return false;
        if (std::fseek(file_, static_cast<long>(at), SEEK_SET) != 0) return false;
        return std::fread(buf, 1, n, file_) == n;
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

    // Reads the record at `pos` (header parsed, data read); returns the position after it.
    std::uint64_t record(std::uint64_t pos, Header& h, std::vector<unsigned char>& data) {
        unsigned char len[4];
        if (!readAt(pos, len, 4)) fail(pos, "a record is cut short (truncated file?)");
        const std::uint64_t hlen = u32(len);
        if (hlen > kMaxHeader || pos + 4 + hlen + 4 > size_)
            fail(pos, "a record header runs past the end of the file (truncated?)");
        std::vector<unsigned char> hb(hlen);
        if (!readAt(pos + 4, hb.data(), hlen) || !readAt(pos + 4 + hlen, len, 4))
            fail(pos, "read error");
        h = parseHeader(hb.data(), hlen, pos);
        std::uint64_t dlen = u32(len);
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
        if (op == kChunk || op == kIndexData) {  // the only data this check reads
            data.resize(dlen);
            if (dlen && !readAt(dpos, data.data(), dlen)) fail(pos, "read error");
        }
        return dpos + dlen;
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

    void chunk(const Header& h, std::vector<unsigned char>& data, std::uint64_t at) {
        const auto c = h.fields.find("compression");
        if (c == h.fields.end()) fail(at, "a chunk without 'compression'");
        const std::uint64_t size = u32field(h, "size", at);
        if (size > kMaxChunk) fail(at, "a chunk of more than 2 GiB");
        std::vector<unsigned char> plain;
        if (c->second == "none") {
            if (data.size() != size) fail(at, "a chunk's size field does not match its data");
            plain.swap(data);
        } else if (c->second == "bz2" || c->second == "lz4") {
            plain.resize(size);
            unsigned int out = static_cast<unsigned int>(size);
            const int rc =
                c->second == "bz2"
                    ? BZ2_bzBuffToBuffDecompress(reinterpret_cast<char*>(plain.data()), &out,
                                                 reinterpret_cast<char*>(data.data()),
                                                 static_cast<unsigned int>(data.size()), 0, 0)
                    : roslz4_buffToBuffDecompress(reinterpret_cast<char*>(data.data()),
                                                  static_cast<unsigned int>(data.size()),
                                                  reinterpret_cast<char*>(plain.data()), &out);
            const bool ok = c->second == "bz2" ? rc == BZ_OK : rc == ROSLZ4_OK;
            if (!ok) fail(at, "a " + c->second + " chunk does not decompress (corrupt)");
            if (out != size) fail(at, "a chunk decompresses to another size than announced");
        } else {
            fail(at, "a chunk with unknown compression '" + c->second + "'");
        }
        // The records inside: connections and messages, each within the chunk.
        std::set<std::uint32_t> starts;
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
            if (op == kMessageData) starts.insert(static_cast<std::uint32_t>(p));
            p += 8 + hlen + dlen;
        }
        chunks_.push_back(at);
        last_starts_ = std::move(starts);
    }

    void indexData(const Header& h, const std::vector<unsigned char>& data, std::uint64_t at) {
        if (chunks_.empty()) fail(at, "index data before any chunk");
        const std::uint64_t count = u32field(h, "count", at);
        if (data.size() != count * 12) fail(at, "index data of the wrong length");
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
    std::FILE* file_ = nullptr;
    std::uint64_t size_ = 0, index_pos_ = 0, chunk_count_ = 0;
    std::vector<std::uint64_t> chunks_;
    std::set<std::uint32_t> last_starts_;
    std::size_t infos_ = 0;
};

}  // namespace

void checkBagStructure(const std::string& path) { Checker(path).run(); }

}  // namespace kfd
