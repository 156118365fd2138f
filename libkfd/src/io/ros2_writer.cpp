#include "kfd/io/ros2_writer.h"

#include <lz4frame.h>
#include <sqlite3.h>
#include <yaml-cpp/yaml.h>
#include <zlib.h>
#include <zstd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <vector>

#include "bag_message.h"
#include "kfd/io/laser_scan.h"
#include "kfd/io/ros2_message.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;

struct FileClose {
    void operator()(std::FILE* f) const { std::fclose(f); }
};

bool endsWith(const std::string& s, const char* x) {
    const std::size_t n = std::strlen(x);
    return s.size() > n && s.compare(s.size() - n, n, x) == 0;
}

// One output topic.
struct Topic {
    std::uint16_t id = 0;
    Ros2Connection c;
    std::uint64_t count = 0;
};

// Where the messages go: a sqlite3 file or an MCAP file.
class Sink {
  public:
    virtual ~Sink() = default;
    virtual void topic(const Topic& t) = 0;
    virtual void message(const Topic& t, std::int64_t time_ns,
                         const std::vector<std::uint8_t>& b) = 0;
    virtual void close(const std::vector<const Topic*>& topics, std::int64_t first,
                       std::int64_t last, std::uint64_t count) = 0;
};

// rosbag2's metadata (metadata.yaml's text, also kept in the .db3's metadata table).
std::string metadataYaml(const std::string& file, const std::vector<const Topic*>& topics,
                         std::int64_t first, std::int64_t last, std::uint64_t count) {
    YAML::Emitter y;
    y << YAML::BeginMap << YAML::Key << "rosbag2_bagfile_information" << YAML::Value
      << YAML::BeginMap;
    y << YAML::Key << "version" << YAML::Value << 5;
    y << YAML::Key << "storage_identifier" << YAML::Value << "sqlite3";
    y << YAML::Key << "duration" << YAML::Value << YAML::BeginMap << YAML::Key << "nanoseconds"
      << YAML::Value << (last - first) << YAML::EndMap;
    y << YAML::Key << "starting_time" << YAML::Value << YAML::BeginMap << YAML::Key
      << "nanoseconds_since_epoch" << YAML::Value << first << YAML::EndMap;
    y << YAML::Key << "message_count" << YAML::Value << count;
    y << YAML::Key << "topics_with_message_count" << YAML::Value << YAML::BeginSeq;
    for (const Topic* t : topics)
        y << YAML::BeginMap << YAML::Key << "topic_metadata" << YAML::Value << YAML::BeginMap
          << YAML::Key << "name" << YAML::Value << t->c.topic << YAML::Key << "type" << YAML::Value
          << t->c.type << YAML::Key << "serialization_format" << YAML::Value << t->c.encoding
          << YAML::Key << "offered_qos_profiles" << YAML::Value << t->c.offered_qos_profiles
          << YAML::EndMap << YAML::Key << "message_count" << YAML::Value << t->count
          << YAML::EndMap;
    y << YAML::EndSeq;
    y << YAML::Key << "compression_format" << YAML::Value << "";
    y << YAML::Key << "compression_mode" << YAML::Value << "";
    y << YAML::Key << "relative_file_paths" << YAML::Value << YAML::BeginSeq << file
      << YAML::EndSeq;
    y << YAML::EndMap << YAML::EndMap;
    return y.c_str();
}

class DbSink : public Sink {
  public:
    DbSink(const std::string& path, const std::string& name) : name_(name) {
        std::error_code ec;
        fs::remove(path, ec);  // a temporary name: anything there is ours
        try {
            open(path);
        } catch (...) {  // the destructor does not run for a constructor that throws
            sqlite3_finalize(insert_);
            sqlite3_close(db_);
            throw;
        }
        file_ = fs::path(name).filename().string();
    }
    void open(const std::string& path) {
        if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE,
                            nullptr) != SQLITE_OK)
            fail("cannot create it");
        exec(
            "PRAGMA journal_mode = MEMORY; PRAGMA synchronous = OFF;"
            "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
            "INSERT INTO schema VALUES (3, 'humble');"
            "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, "
            "metadata TEXT NOT NULL);"
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
            " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
            "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
            "BEGIN;");
        if (sqlite3_prepare_v2(db_,
                               "INSERT INTO messages(topic_id, timestamp, data) VALUES (?, ?, ?)",
                               -1, &insert_, nullptr) != SQLITE_OK)
            fail("cannot prepare it");
    }
    ~DbSink() override {
        sqlite3_finalize(insert_);
        sqlite3_close(db_);
    }
    void topic(const Topic& t) override {
        sqlite3_stmt* s = nullptr;
        if (sqlite3_prepare_v2(db_, "INSERT INTO topics VALUES (?, ?, ?, ?, ?)", -1, &s, nullptr) !=
            SQLITE_OK)
            fail("cannot add a topic");
        sqlite3_bind_int(s, 1, t.id);
        sqlite3_bind_text(s, 2, t.c.topic.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(s, 3, t.c.type.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(s, 4, t.c.encoding.c_str(), -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(s, 5, t.c.offered_qos_profiles.c_str(), -1, SQLITE_TRANSIENT);
        const int rc = sqlite3_step(s);
        sqlite3_finalize(s);
        if (rc != SQLITE_DONE) fail("cannot add a topic");
    }
    void message(const Topic& t, std::int64_t time_ns,
                 const std::vector<std::uint8_t>& b) override {
        sqlite3_reset(insert_);
        sqlite3_bind_int(insert_, 1, t.id);
        sqlite3_bind_int64(insert_, 2, time_ns);
        sqlite3_bind_blob(insert_, 3, b.empty() ? "" : static_cast<const void*>(b.data()),
                          static_cast<int>(b.size()), SQLITE_STATIC);
        if (sqlite3_step(insert_) != SQLITE_DONE) fail("failed writing a message");
    }
    void close(const std::vector<const Topic*>& topics, std::int64_t first, std::int64_t last,
               std::uint64_t count) override {
        const std::string yaml = metadataYaml(file_, topics, first, last, count);
        sqlite3_stmt* s = nullptr;
        if (sqlite3_prepare_v2(db_,
                               "INSERT INTO metadata(metadata_version, metadata) VALUES (5, ?)", -1,
                               &s, nullptr) != SQLITE_OK)
            fail("cannot write its metadata");
        sqlite3_bind_text(s, 1, yaml.c_str(), -1, SQLITE_TRANSIENT);
        const int rc = sqlite3_step(s);
        sqlite3_finalize(s);
        if (rc != SQLITE_DONE) fail("cannot write its metadata");
        exec("COMMIT; CREATE INDEX timestamp_idx ON messages (timestamp ASC);");
        sqlite3_finalize(insert_);
        insert_ = nullptr;
        if (sqlite3_close(db_) != SQLITE_OK) fail("cannot close it");
        db_ = nullptr;
    }

  private:
    void exec(const char* sql) {
        if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) != SQLITE_OK) fail("cannot write it");
    }
    [[noreturn]] void fail(const char* what) const {
        const int err = db_ ? sqlite3_system_errno(db_) : errno;
        throw BagError("cannot write " + name_ + ": " +
                           (err ? std::string(std::strerror(err)) + " (" : "(") + what +
                           "; sqlite: " + (db_ ? sqlite3_errmsg(db_) : "no database") + ")",
                       name_);
    }
    std::string name_, file_;
    sqlite3* db_ = nullptr;
    sqlite3_stmt* insert_ = nullptr;
};

// MCAP records (https://mcap.dev/spec): little-endian fields, strings and byte arrays with a
// u32 length, maps with a u32 byte length.
class Record {
  public:
    explicit Record(std::uint8_t op) : op_(op) {}
    template <class T>
    Record& num(T v) {
        for (std::size_t i = 0; i < sizeof(T); ++i)
            b_.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i)));
        return *this;
    }
    Record& str(const std::string& s) {
        num<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
        b_.insert(b_.end(), s.begin(), s.end());
        return *this;
    }
    Record& map(const std::map<std::string, std::string>& m) {
        Record inner(0);
        for (const auto& [k, v] : m) inner.str(k).str(v);
        num<std::uint32_t>(static_cast<std::uint32_t>(inner.b_.size()));
        b_.insert(b_.end(), inner.b_.begin(), inner.b_.end());
        return *this;
    }
    Record& raw(const std::vector<std::uint8_t>& d) {
        b_.insert(b_.end(), d.begin(), d.end());
        return *this;
    }
    std::vector<std::uint8_t> bytes() const {
        Record r(0);
        r.b_.push_back(op_);
        r.num<std::uint64_t>(b_.size());
        r.b_.insert(r.b_.end(), b_.begin(), b_.end());
        return r.b_;
    }

  private:
    std::uint8_t op_;
    std::vector<std::uint8_t> b_;
};

// An MCAP file as rosbag2 writes one: Schema and Channel records as topics appear, messages in
// chunks of about 1 MiB (zstd, lz4 or none), each followed by its MessageIndex records; a summary
// (schemas, channels, statistics, chunk indexes) so that indexed readers can seek.
class McapSink : public Sink {
  public:
    McapSink(const std::string& path, const std::string& name, std::string compression)
        : name_(name), compression_(std::move(compression)) {
        f_.reset(std::fopen(path.c_str(), "wb"));  // closed even when this throws
        if (!f_) fail("cannot create it");
        put({0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'});
        put(Record(0x01).str("ros2").str("kfd").bytes());
    }
    void topic(const Topic& t) override {
        const std::string enc = t.c.schema_encoding.empty() ? "ros2msg" : t.c.schema_encoding;
        const std::string data =
            t.c.schema_encoding.empty() ? ros2Definition(t.c.type) : t.c.schema_data;
        schemas_.push_back(
            Record(0x03).num<std::uint16_t>(t.id).str(t.c.type).str(enc).str(data).bytes());
        auto meta = t.c.metadata;
        if (!t.c.offered_qos_profiles.empty())
            meta["offered_qos_profiles"] = t.c.offered_qos_profiles;
        channels_.push_back(Record(0x04)
                                .num<std::uint16_t>(t.id)
                                .num<std::uint16_t>(t.id)
                                .str(t.c.topic)
                                .str(t.c.encoding)
                                .map(meta)
                                .bytes());
        put(schemas_.back());  // before the chunk that uses it
        put(channels_.back());
    }
    void message(const Topic& t, std::int64_t time_ns,
                 const std::vector<std::uint8_t>& b) override {
        const auto ns = static_cast<std::uint64_t>(time_ns);
        index_[t.id].push_back({ns, chunk_.size()});
        const auto r = Record(0x05)
                           .num<std::uint16_t>(t.id)
                           .num<std::uint32_t>(static_cast<std::uint32_t>(t.count))
                           .num<std::uint64_t>(ns)
                           .num<std::uint64_t>(ns)
                           .raw(b)
                           .bytes();
        chunk_.insert(chunk_.end(), r.begin(), r.end());
        chunk_start_ = chunk_count_ ? std::min(chunk_start_, ns) : ns;
        chunk_end_ = chunk_count_ ? std::max(chunk_end_, ns) : ns;
        ++chunk_count_;
        if (chunk_.size() >= kChunkBytes) flushChunk();
    }
    void close(const std::vector<const Topic*>& topics, std::int64_t first, std::int64_t last,
               std::uint64_t count) override {
        flushChunk();
        put(Record(0x0F).num<std::uint32_t>(0).bytes());  // DataEnd (no CRC)
        const std::uint64_t summary = at_;
        for (const auto& s : schemas_) put(s);
        for (const auto& c : channels_) put(c);
        Record stats(0x0B);
        stats.num<std::uint64_t>(count)
            .num<std::uint16_t>(static_cast<std::uint16_t>(schemas_.size()))
            .num<std::uint32_t>(static_cast<std::uint32_t>(channels_.size()))
            .num<std::uint32_t>(0)
            .num<std::uint32_t>(0)
            .num<std::uint32_t>(static_cast<std::uint32_t>(chunk_indexes_.size()))
            .num<std::uint64_t>(static_cast<std::uint64_t>(first))
            .num<std::uint64_t>(static_cast<std::uint64_t>(last))
            .num<std::uint32_t>(static_cast<std::uint32_t>(topics.size() * 10));
        for (const Topic* t : topics) stats.num<std::uint16_t>(t->id).num<std::uint64_t>(t->count);
        put(stats.bytes());
        for (const auto& ci : chunk_indexes_) put(ci);
        put(Record(0x02)
                .num<std::uint64_t>(summary)
                .num<std::uint64_t>(0)
                .num<std::uint32_t>(0)
                .bytes());
        put({0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'});
        if (std::fflush(f_.get()) != 0) fail("failed writing it");
        const int rc = std::fclose(f_.release());
        if (rc != 0) fail("failed closing it");
    }

  private:
    static constexpr std::size_t kChunkBytes = 1u << 20;

    std::vector<std::uint8_t> compress(const std::vector<std::uint8_t>& in) const {
        std::vector<std::uint8_t> out;
        if (compression_ == "zstd") {
            out.resize(ZSTD_compressBound(in.size()));
            const std::size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 1);
            if (ZSTD_isError(n)) fail("zstd failed");
            out.resize(n);
        } else if (compression_ == "lz4") {
            out.resize(LZ4F_compressFrameBound(in.size(), nullptr));
            const std::size_t n =
                LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr);
            if (LZ4F_isError(n)) fail("lz4 failed");
            out.resize(n);
        } else {
            out = in;
        }
        return out;
    }
    void flushChunk() {
        if (chunk_count_ == 0) return;
        const auto data = compress(chunk_);
        const auto crc =
            static_cast<std::uint32_t>(crc32(0L, chunk_.data(), static_cast<uInt>(chunk_.size())));
        const auto rec = Record(0x06)
                             .num<std::uint64_t>(chunk_start_)
                             .num<std::uint64_t>(chunk_end_)
                             .num<std::uint64_t>(chunk_.size())
                             .num<std::uint32_t>(crc)
                             .str(compression_)
                             .num<std::uint64_t>(data.size())
                             .raw(data)
                             .bytes();
        const std::uint64_t chunk_at = at_;
        put(rec);
        const std::uint64_t index_at = at_;
        std::map<std::uint16_t, std::uint64_t> offsets;
        for (const auto& [channel, entries] : index_) {
            Record mi(0x07);
            mi.num<std::uint16_t>(channel).num<std::uint32_t>(
                static_cast<std::uint32_t>(entries.size() * 16));
            for (const auto& [t, off] : entries) mi.num<std::uint64_t>(t).num<std::uint64_t>(off);
            offsets[channel] = at_;
            put(mi.bytes());
        }
        Record ci(0x08);
        ci.num<std::uint64_t>(chunk_start_)
            .num<std::uint64_t>(chunk_end_)
            .num<std::uint64_t>(chunk_at)
            .num<std::uint64_t>(rec.size())
            .num<std::uint32_t>(static_cast<std::uint32_t>(offsets.size() * 10));
        for (const auto& [channel, off] : offsets)
            ci.num<std::uint16_t>(channel).num<std::uint64_t>(off);
        ci.num<std::uint64_t>(at_ - index_at)
            .str(compression_)
            .num<std::uint64_t>(data.size())
            .num<std::uint64_t>(chunk_.size());
        chunk_indexes_.push_back(ci.bytes());
        chunk_.clear();
        index_.clear();
        chunk_count_ = 0;
    }
    void put(const std::vector<std::uint8_t>& b) {
        if (!b.empty() && std::fwrite(b.data(), 1, b.size(), f_.get()) != b.size())
            fail("failed writing it");
        at_ += b.size();
    }
    [[noreturn]] void fail(const char* what) const {
        const int err = errno;
        throw BagError("cannot write " + name_ + ": " +
                           (err ? std::string(std::strerror(err)) + " (" : "(") + what + ")",
                       name_);
    }
    std::string name_, compression_;
    std::unique_ptr<std::FILE, FileClose> f_;
    std::uint64_t at_ = 0;
    std::vector<std::vector<std::uint8_t>> schemas_, channels_, chunk_indexes_;
    std::vector<std::uint8_t> chunk_;
    std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> index_;
    std::uint64_t chunk_start_ = 0, chunk_end_ = 0, chunk_count_ = 0;
};

// A ROS 1 message of a type kfd reads, as CDR under its ROS 2 type (its lengths checked first,
// as for every message kfd deserializes: another topic's may be corrupt); false for other types.
bool toCdr(const NativeMessage& m, std::string& type, std::vector<std::uint8_t>& out) {
    if (const auto ls = instantiateChecked<sensor_msgs::LaserScan>(m)) {
        type = "sensor_msgs/msg/LaserScan";
        out = encodeRos2(*ls);
    } else if (const auto od = instantiateChecked<nav_msgs::Odometry>(m)) {
        type = "nav_msgs/msg/Odometry";
        out = encodeRos2(*od);
    } else if (const auto tf = instantiateChecked<tf2_msgs::TFMessage>(m)) {
        type = "tf2_msgs/msg/TFMessage";
        out = encodeRos2(*tf);
    } else {
        return false;
    }
    return true;
}

// An MCAP output's chunk compression (MCAP's names: "" none, "lz4", "zstd").
std::string mcapCompression(const BagWriterOptions& o) {
    switch (o.compression) {
        case BagWriterOptions::Compression::None:
            return "";
        case BagWriterOptions::Compression::Lz4:
            return "lz4";
        case BagWriterOptions::Compression::Bz2:
            throw BagError("an MCAP file has no bz2 chunks (none, lz4 or zstd)");
        default:
            return "zstd";
    }
}

}  // namespace

bool ros2OutputFormat(const std::string& name, LogFormat& format) {
    if (endsWith(name, ".db3")) {
        format = LogFormat::Rosbag2;
        return true;
    }
    if (endsWith(name, ".mcap")) {
        format = LogFormat::Mcap;
        return true;
    }
    return false;
}

struct Ros2Writer::Impl {
    std::string name;
    BagWriterOptions options;
    std::unique_ptr<Sink> sink;
    std::map<std::pair<std::string, std::string>, Topic> topics;  // (topic, type)
    std::vector<const Topic*> order;
    std::size_t written = 0, left_out = 0;
    std::int64_t first = 0, last = 0;

    Topic& topicOf(const Ros2Connection& c) {
        auto it = topics.find({c.topic, c.type});
        if (it != topics.end()) return it->second;
        Topic& t = topics[{c.topic, c.type}];
        t.id = static_cast<std::uint16_t>(order.size() + 1);
        t.c = c;
        order.push_back(&t);
        sink->topic(t);
        return t;
    }
    void write(Topic& t, std::int64_t time_ns, const std::vector<std::uint8_t>& bytes) {
        sink->message(t, time_ns, bytes);
        ++t.count;
        first = written ? std::min(first, time_ns) : time_ns;
        last = written ? std::max(last, time_ns) : time_ns;
        ++written;
    }
    // The message's connection and time in the output: its own (ROS 2) or its ROS 2 form.
    std::int64_t timeOf(const NativeMessage& m) const {
        return m.ros2 ? m.time_ns : static_cast<std::int64_t>(m.time.toNSec());
    }
    Ros2Connection ros1Connection(const NativeMessage& m, const std::string& type) const {
        Ros2Connection c;
        c.topic = m.topic();
        c.type = type;
        return c;
    }
};

Ros2Writer::Ros2Writer(const std::string& path, LogFormat format, const BagWriterOptions& options,
                       const std::string& name)
    : impl_(std::make_unique<Impl>()) {
    impl_->name = name.empty() ? path : name;
    impl_->options = options;
    if (format == LogFormat::Rosbag2)
        impl_->sink = std::make_unique<DbSink>(path, impl_->name);
    else
        impl_->sink = std::make_unique<McapSink>(path, impl_->name, mcapCompression(options));
}
Ros2Writer::~Ros2Writer() = default;

void Ros2Writer::copy(const NativeMessage& m) {
    Impl& d = *impl_;
    if (m.ros2) {
        d.write(d.topicOf(*m.ros2), m.time_ns, m.bytes);
        return;
    }
    std::string type;
    std::vector<std::uint8_t> cdr;
    if (!toCdr(m, type, cdr)) {
        ++d.left_out;
        return;
    }
    d.write(d.topicOf(d.ros1Connection(m, type)), d.timeOf(m), cdr);
}

std::size_t Ros2Writer::writeScan(const NativeMessage& original,
                                  const mrpt::obs::CObservation2DRangeScan& cleaned) {
    Impl& d = *impl_;
    auto ls = original.instantiate<sensor_msgs::LaserScan>();
    if (!ls)
        throw BagError(d.name + ": the message on " + original.topic() + " is not a LaserScan",
                       d.name);
    const std::size_t marked = markRemovedBeams(*ls, cleaned, d.options.removed);
    Topic& t = original.ros2 && original.ros2->encoding == "cdr"
                   ? d.topicOf(*original.ros2)
                   : d.topicOf(d.ros1Connection(original, "sensor_msgs/msg/LaserScan"));
    d.write(t, d.timeOf(original), encodeRos2(*ls));
    return marked;
}

void Ros2Writer::close() {
    Impl& d = *impl_;
    d.sink->close(d.order, d.first, d.last, d.written);
}

std::size_t Ros2Writer::messagesWritten() const { return impl_->written; }
std::size_t Ros2Writer::messagesLeftOut() const { return impl_->left_out; }

}  // namespace kfd
