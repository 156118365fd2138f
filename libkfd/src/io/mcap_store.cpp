// MCAP (https://mcap.dev/spec), read by kfd itself (no MCAP library is packaged for Debian 12):
// magic, then records (opcode u8, length u64, content) up to DataEnd; Schema, Channel and Message
// records on their own or inside Chunks (compression "", "lz4" frames or "zstd"). Messages are
// read in file order (rosbag2 writes them as they arrive). Every length is checked against its
// record and every chunk against its announced size and CRC before its records are read.
#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "message_store.h"
#include "ros2_store.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;

struct FileClose {
    void operator()(std::FILE* f) const { std::fclose(f); }
};

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
// A chunk that decompresses to more than this is refused (memory bounded whatever it claims).
constexpr std::uint64_t kMaxChunkBytes = 512ull << 20;
constexpr std::uint64_t kMaxRecordBytes = 1ull << 30;

enum Op : std::uint8_t {
    kHeader = 0x01,
    kFooter = 0x02,
    kSchema = 0x03,
    kChannel = 0x04,
    kMessage = 0x05,
    kChunk = 0x06,
    kDataEnd = 0x0F,
};

// Little-endian fields of one record's content, each checked against the content's end.
class Fields {
  public:
    Fields(const std::uint8_t* p, std::size_t n, const char* record)
        : p_(p), n_(n), record_(record) {}
    template <class T>
    T num(const char* field) {
        need(sizeof(T), field);
        T v = 0;
        for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<T>(T(p_[at_ + i]) << (8 * i));
        at_ += sizeof(T);
        return v;
    }
    std::string str(const char* field) {
        const std::uint32_t len = num<std::uint32_t>(field);
        need(len, field);
        std::string s(reinterpret_cast<const char*>(p_ + at_), len);
        at_ += len;
        return s;
    }
    std::map<std::string, std::string> map(const char* field) {
        const std::uint32_t len = num<std::uint32_t>(field);
        need(len, field);
        const std::size_t end = at_ + len;
        std::map<std::string, std::string> m;
        while (at_ < end) {
            std::string k = str(field);
            m[k] = str(field);
        }
        if (at_ != end)
            throw BagError(std::string(record_) + ": " + field + ": a length that lies");
        return m;
    }
    const std::uint8_t* rest(std::size_t& n) {
        n = n_ - at_;
        return p_ + at_;
    }
    void need(std::uint64_t k, const char* field) const {
        if (k > n_ - at_)
            throw BagError(std::string(record_) + ": " + field + ": " + std::to_string(k) +
                           " bytes announced, " + std::to_string(n_ - at_) +
                           " left in the record (a length that lies, or a truncated file)");
    }

  private:
    const std::uint8_t* p_;
    std::size_t n_, at_ = 0;
    const char* record_;
};

// Room for more output: doubled, up to the announced size. A corrupt size field allocates
// nothing: the output grows with what the data holds.
void grow(std::vector<std::uint8_t>& out, std::size_t used, std::uint64_t size) {
    if (used < out.size()) return;
    const std::size_t next = std::max<std::size_t>(out.size() * 2, 64u << 10);
    out.resize(static_cast<std::size_t>(std::min<std::uint64_t>(next, size)));
}

std::size_t unzstd(const std::uint8_t* p, std::size_t n, std::uint64_t size,
                   std::vector<std::uint8_t>& out) {
    ZSTD_DStream* z = ZSTD_createDStream();
    if (!z) throw BagError("cannot start zstd");
    ZSTD_inBuffer in{p, n, 0};
    std::size_t used = 0, rc = 1;
    while (rc != 0 && !ZSTD_isError(rc) && used < size) {
        grow(out, used, size);
        ZSTD_outBuffer o{out.data(), out.size(), used};
        const std::size_t before_in = in.pos, before_out = used;
        rc = ZSTD_decompressStream(z, &o, &in);
        used = o.pos;
        if (in.pos == before_in && used == before_out && used < out.size()) break;  // stuck
    }
    if (used == size && !ZSTD_isError(rc) && rc != 0) {  // all output: is the frame complete?
        std::uint8_t extra = 0;
        ZSTD_outBuffer o{&extra, 1, 0};
        rc = ZSTD_decompressStream(z, &o, &in);
        if (o.pos) used = size + 1;
    }
    ZSTD_freeDStream(z);
    if (ZSTD_isError(rc) || rc != 0 || used != size)
        throw BagError(std::string("a zstd chunk that does not decompress to its size (") +
                       (ZSTD_isError(rc) ? ZSTD_getErrorName(rc) : "size differs") + ")");
    return used;
}

std::size_t unlz4(const std::uint8_t* p, std::size_t n, std::uint64_t size,
                  std::vector<std::uint8_t>& out) {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)))
        throw BagError("cannot start lz4");
    std::size_t in_at = 0, used = 0, rc = 1;
    while (rc != 0 && in_at < n) {
        if (used == size) {  // output complete, input left: more than announced
            used = size + 1;
            break;
        }
        grow(out, used, size);
        std::size_t src = n - in_at, dst = out.size() - used;
        rc = LZ4F_decompress(ctx, out.data() + used, &dst, p + in_at, &src, nullptr);
        if (LZ4F_isError(rc)) break;
        in_at += src;
        used += dst;
        if (src == 0 && dst == 0) break;
    }
    LZ4F_freeDecompressionContext(ctx);
    if (LZ4F_isError(rc) || rc != 0 || used != size)
        throw BagError(std::string("an lz4 chunk that does not decompress to its size (") +
                       (LZ4F_isError(rc) ? LZ4F_getErrorName(rc) : "size differs") + ")");
    return used;
}

std::vector<std::uint8_t> decompress(const std::string& how, const std::uint8_t* p, std::size_t n,
                                     std::uint64_t size) {
    if (size > kMaxChunkBytes)
        throw BagError("a chunk of " + std::to_string(size) +
                       " bytes uncompressed (kfd reads chunks up to 512 MiB)");
    std::vector<std::uint8_t> out;
    if (how.empty()) {
        if (n != size) throw BagError("an uncompressed chunk whose size does not match its data");
        out.assign(p, p + n);
    } else if (how == "zstd") {
        out.resize(unzstd(p, n, size, out));
    } else if (how == "lz4") {
        out.resize(unlz4(p, n, size, out));
    } else {
        throw BagError("a chunk compressed with '" + how + "' (MCAP readers know \"\", lz4, zstd)");
    }
    return out;
}

class McapStore : public MessageStore {
  public:
    McapStore(const std::string& path, bool check) : path_(path) {
        std::error_code ec;
        if (!fs::is_regular_file(path, ec)) throw BagError(path + ": no such file", path);
        size_ = fs::file_size(path, ec);
        file_.reset(std::fopen(path.c_str(), "rb"));  // closed even when this throws
        if (!file_) throw BagError(path + ": cannot open it", path);
        std::uint8_t magic[8] = {};
        if (size_ < 8 || std::fread(magic, 1, 8, file_.get()) != 8 ||
            std::memcmp(magic, kMagic, 8) != 0)
            throw BagError(path + ": not an MCAP file (no MCAP magic)", path);
        (void)check;  // the pass below walks every record and chunk
        scan();
    }

    std::map<std::string, TopicInfo> topics() override { return topics_; }
    std::unique_ptr<Cursor> cursor(const std::string& topic, bool) override {
        return std::make_unique<Walk>(*this, topic);
    }
    std::string kind() const override { return "MCAP"; }
    std::string compression() const override { return compression_; }

  private:
    // Walks the data section: records on their own and inside chunks, in file order.
    class Walk : public Cursor {
      public:
        Walk(McapStore& s, std::string topic) : s_(s), topic_(std::move(topic)), at_(8) {
            if (topic_.empty())
                size_ = s.messages_;
            else if (s.topics_.count(topic_))
                size_ = s.topics_.at(topic_).count;
        }
        bool next(NativeMessage& out) override {
            for (;;) {
                if (chunk_at_ < chunk_.size()) {
                    if (fromChunk(out)) return true;
                    continue;
                }
                if (done_) return false;
                if (!record()) return false;
                if (op_ != kMessage) continue;
                try {
                    if (message(buf_.data(), buf_.size(), out)) return true;
                } catch (const BagError& e) {
                    s_.fail(record_at_, e.what());
                }
            }
        }
        std::size_t size() const override { return size_; }
        // One record of the file; false at DataEnd, the Footer or the end of the file.
        bool record() {
            if (at_ + 9 > s_.size_) {
                if (at_ != s_.size_) s_.fail(at_, "a record header cut short (truncated file)");
                done_ = true;
                return false;
            }
            std::uint8_t h[9];
            s_.readAt(at_, h, 9);
            op_ = h[0];
            std::uint64_t len = 0;
            for (int i = 0; i < 8; ++i) len |= std::uint64_t(h[1 + i]) << (8 * i);
            if (len > s_.size_ - at_ - 9)
                s_.fail(at_, "a record of " + std::to_string(len) + " bytes, past the file's end " +
                                 "(truncated, or a length that lies)");
            if (len > kMaxRecordBytes) s_.fail(at_, "a record of more than 1 GiB");
            record_at_ = at_;
            at_ += 9 + len;
            if (op_ == kDataEnd || op_ == kFooter) {
                done_ = true;
                return false;
            }
            if (op_ != kMessage && op_ != kChunk && op_ != kSchema && op_ != kChannel) {
                buf_.clear();
                return true;  // skipped (indexes, attachments, metadata, statistics)
            }
            buf_.resize(static_cast<std::size_t>(len));
            s_.readAt(record_at_ + 9, buf_.data(), buf_.size());
            try {
                if (op_ == kChunk) openChunk();
                if (op_ == kSchema) s_.onSchema(buf_.data(), buf_.size());
                if (op_ == kChannel) s_.onChannel(buf_.data(), buf_.size());
            } catch (const BagError& e) {
                s_.fail(record_at_, e.what());
            }
            return true;
        }
        std::uint8_t op() const { return op_; }

      private:
        void openChunk() {
            Fields f(buf_.data(), buf_.size(), "chunk");
            f.num<std::uint64_t>("message_start_time");
            f.num<std::uint64_t>("message_end_time");
            const auto size = f.num<std::uint64_t>("uncompressed_size");
            const auto crc = f.num<std::uint32_t>("uncompressed_crc");
            const std::string how = f.str("compression");
            const auto len = f.num<std::uint64_t>("records length");
            f.need(len, "records");
            std::size_t n = 0;
            const std::uint8_t* p = f.rest(n);
            chunk_ = decompress(how, p, static_cast<std::size_t>(len), size);
            if (crc != 0 && crc32(0L, chunk_.data(), static_cast<uInt>(chunk_.size())) != crc)
                throw BagError("a chunk whose CRC does not match its records (corrupt)");
            if (!how.empty()) s_.compression_ = how;
            chunk_at_ = 0;
        }
        // One record of the open chunk: true when it was a message for `out`.
        bool fromChunk(NativeMessage& out) {
            try {
                if (chunk_.size() - chunk_at_ < 9)
                    throw BagError("a record header cut short inside a chunk");
                const std::uint8_t op = chunk_[chunk_at_];
                std::uint64_t len = 0;
                for (int i = 0; i < 8; ++i)
                    len |= std::uint64_t(chunk_[chunk_at_ + 1 + i]) << (8 * i);
                if (len > chunk_.size() - chunk_at_ - 9)
                    throw BagError("a record inside a chunk that runs past the chunk's end");
                const std::uint8_t* p = chunk_.data() + chunk_at_ + 9;
                chunk_at_ += 9 + static_cast<std::size_t>(len);
                if (chunk_at_ == chunk_.size()) chunk_.clear(), chunk_at_ = 0;
                if (op == kSchema) s_.onSchema(p, static_cast<std::size_t>(len));
                if (op == kChannel) s_.onChannel(p, static_cast<std::size_t>(len));
                return op == kMessage && message(p, static_cast<std::size_t>(len), out);
            } catch (const BagError& e) {
                chunk_.clear();
                chunk_at_ = 0;
                s_.fail(record_at_, e.what());
            }
        }
        bool message(const std::uint8_t* p, std::size_t n, NativeMessage& out) {
            Fields f(p, n, "message");
            const auto channel = f.num<std::uint16_t>("channel_id");
            f.num<std::uint32_t>("sequence");
            const auto log_time = f.num<std::uint64_t>("log_time");
            f.num<std::uint64_t>("publish_time");
            const auto c = s_.channels_.find(channel);
            if (c == s_.channels_.end())
                throw BagError("a message on channel " + std::to_string(channel) +
                               ", which no Channel record defines before it");
            if (!topic_.empty() && c->second->topic != topic_) return false;
            if (log_time / 1000000000ull > 0xffffffffull)
                throw BagError("a message whose log_time is after 2106");
            std::size_t len = 0;
            const std::uint8_t* data = f.rest(len);
            out.connection = nullptr;
            out.ros2 = c->second.get();
            out.time_ns = static_cast<std::int64_t>(log_time);
            out.time.fromNSec(log_time);
            out.bytes.assign(data, data + len);
            return true;
        }

        McapStore& s_;
        std::string topic_;
        std::uint64_t at_, record_at_ = 0;
        std::uint8_t op_ = 0;
        bool done_ = false;
        std::vector<std::uint8_t> buf_, chunk_;
        std::size_t chunk_at_ = 0, size_ = 0;
    };

    struct Schema {
        std::string name, encoding, data;
    };

    void readAt(std::uint64_t at, std::uint8_t* p, std::size_t n) {
        if (fseeko(file_.get(), static_cast<off_t>(at), SEEK_SET) != 0 ||
            std::fread(p, 1, n, file_.get()) != n)
            fail(at, "cannot read it");
    }
    [[noreturn]] void fail(std::uint64_t at, const std::string& what) const {
        throw BagError(path_ + ": byte " + std::to_string(at) + ": " + what, path_);
    }
    void onSchema(const std::uint8_t* p, std::size_t n) {
        Fields f(p, n, "schema");
        const auto id = f.num<std::uint16_t>("id");
        Schema s;
        s.name = f.str("name");
        s.encoding = f.str("encoding");
        s.data = f.str("data");
        schemas_[id] = std::move(s);
    }
    void onChannel(const std::uint8_t* p, std::size_t n) {
        Fields f(p, n, "channel");
        const auto id = f.num<std::uint16_t>("id");
        const auto schema = f.num<std::uint16_t>("schema_id");
        auto c = std::make_unique<Ros2Connection>();
        c->topic = f.str("topic");
        c->encoding = f.str("message_encoding");
        c->metadata = f.map("metadata");
        if (schema != 0) {
            const auto s = schemas_.find(schema);
            if (s == schemas_.end())
                throw BagError("channel " + c->topic + " names schema " + std::to_string(schema) +
                               ", which no Schema record defines");
            c->type = s->second.name;
            c->schema_encoding = s->second.encoding;
            c->schema_data = s->second.data;
        }
        if (c->metadata.count("offered_qos_profiles"))
            c->offered_qos_profiles = c->metadata.at("offered_qos_profiles");
        if (channels_.count(id)) return;  // the same channel again (summary, another chunk)
        channels_[id] = std::move(c);
    }
    // The first pass: every record checked, the topics counted.
    void scan() {
        Walk w(*this, {});
        NativeMessage m;
        while (w.next(m)) {
            TopicInfo& t = topics_[m.ros2->topic];
            const double s = static_cast<double>(m.time_ns) * 1e-9;
            t.type = m.ros2->type;
            t.first = t.count ? std::min(t.first, s) : s;
            t.last = t.count ? std::max(t.last, s) : s;
            ++t.count;
            ++messages_;
        }
        for (const auto& [id, c] : channels_)
            if (!topics_.count(c->topic)) topics_[c->topic].type = c->type;
    }

    std::string path_;
    std::uint64_t size_ = 0;
    std::unique_ptr<std::FILE, FileClose> file_;
    std::string compression_ = "none";
    std::map<std::uint16_t, Schema> schemas_;
    std::map<std::uint16_t, std::unique_ptr<Ros2Connection>> channels_;
    std::map<std::string, TopicInfo> topics_;
    std::size_t messages_ = 0;
};

}  // namespace

std::unique_ptr<MessageStore> openMcap(const std::string& path, bool check) {
    return std::make_unique<McapStore>(path, check);
}

}  // namespace kfd
