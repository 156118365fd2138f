// rosbag2's sqlite3 storage (Humble: schema 3; Jazzy: schema 4): a folder with metadata.yaml
// and one or more .db3 files (split bags, read one after the other), or one .db3 on its own.
#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "message_store.h"
#include "ros2_store.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;

// A message larger than this is refused (a corrupt length would otherwise be allocated).
constexpr std::int64_t kMaxMessageBytes = 256ll << 20;

struct Db {
    sqlite3* db = nullptr;
    std::string path;
    ~Db() {
        if (db) sqlite3_close(db);
    }
};

class Statement {
  public:
    Statement(const Db& db, const std::string& sql) : db_(db) {
        if (sqlite3_prepare_v2(db.db, sql.c_str(), -1, &st_, nullptr) != SQLITE_OK)
            fail("cannot query it");
    }
    ~Statement() { sqlite3_finalize(st_); }
    Statement(const Statement&) = delete;
    Statement& operator=(const Statement&) = delete;
    /// True while a row comes.
    bool step() {
        const int rc = sqlite3_step(st_);
        if (rc == SQLITE_ROW) return true;
        if (rc == SQLITE_DONE) return false;
        fail("cannot read it");
        return false;
    }
    std::int64_t integer(int col) const { return sqlite3_column_int64(st_, col); }
    std::string text(int col) const {
        const auto* t = sqlite3_column_text(st_, col);
        return t ? reinterpret_cast<const char*>(t) : "";
    }
    sqlite3_stmt* get() const { return st_; }
    [[noreturn]] void fail(const char* what) const {
        throw BagError(db_.path + ": " + what +
                           " as a rosbag2 sqlite3 file (sqlite: " + sqlite3_errmsg(db_.db) + ")",
                       db_.path);
    }

  private:
    const Db& db_;
    sqlite3_stmt* st_ = nullptr;
};

std::unique_ptr<Db> openDb(const std::string& path) {
    auto d = std::make_unique<Db>();
    d->path = path;
    // immutable: no lock, no journal, nothing written next to the file (read-only media too).
    const std::string uri = "file:" + path + "?immutable=1";
    if (sqlite3_open_v2(uri.c_str(), &d->db, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr) !=
        SQLITE_OK)
        throw BagError(path + ": cannot open it as a sqlite3 file (sqlite: " +
                           (d->db ? sqlite3_errmsg(d->db) : "out of memory") + ")",
                       path);
    bool topics = false, messages = false;
    Statement s(*d, "SELECT name FROM sqlite_master WHERE type = 'table'");
    while (s.step()) {
        topics |= s.text(0) == "topics";
        messages |= s.text(0) == "messages";
    }
    if (!topics || !messages)
        throw BagError(path + ": a sqlite3 file without rosbag2's tables 'topics' and 'messages'",
                       path);
    return d;
}

bool hasColumn(const Db& d, const char* table, const char* column) {
    Statement s(d, std::string("PRAGMA table_info(") + table + ")");
    while (s.step())
        if (s.text(1) == column) return true;
    return false;
}

class Rosbag2Store : public MessageStore {
  public:
    Rosbag2Store(const std::string& path, std::vector<std::string> files, std::string compression)
        : path_(path), compression_(std::move(compression)) {
        for (const auto& f : files) dbs_.push_back(openDb(f));
        for (std::size_t i = 0; i < dbs_.size(); ++i) readTopics(i);
    }

    std::map<std::string, TopicInfo> topics() override {
        std::map<std::string, TopicInfo> out;
        for (std::size_t i = 0; i < dbs_.size(); ++i) {
            Statement s(*dbs_[i],
                        "SELECT topic_id, count(*), min(timestamp), max(timestamp) FROM messages "
                        "GROUP BY topic_id");
            while (s.step()) {
                const auto c = conns_.find({i, s.integer(0)});
                if (c == conns_.end()) continue;
                TopicInfo& t = out[c->second->topic];
                const double first = static_cast<double>(s.integer(2)) * 1e-9;
                const double last = static_cast<double>(s.integer(3)) * 1e-9;
                t.first = t.count ? std::min(t.first, first) : first;
                t.last = t.count ? std::max(t.last, last) : last;
                t.count += static_cast<std::size_t>(s.integer(1));
            }
        }
        for (const auto& [key, c] : conns_) out[c->topic].type = c->type;
        return out;
    }

    std::unique_ptr<Cursor> cursor(const std::string& topic, bool) override {
        return std::make_unique<DbCursor>(*this, topic);
    }
    std::string kind() const override { return "rosbag2 (sqlite3)"; }
    std::string compression() const override { return compression_; }

  private:
    class DbCursor : public Cursor {
      public:
        DbCursor(Rosbag2Store& store, std::string topic) : store_(store), topic_(std::move(topic)) {
            for (std::size_t i = 0; i < store_.dbs_.size(); ++i) {
                Statement s(*store_.dbs_[i], "SELECT count(*) FROM messages" + where(i));
                if (s.step()) size_ += static_cast<std::size_t>(s.integer(0));
            }
        }
        bool next(NativeMessage& out) override {
            while (file_ < store_.dbs_.size()) {
                if (!st_)
                    st_ = std::make_unique<Statement>(
                        *store_.dbs_[file_],
                        "SELECT topic_id, timestamp, length(data), data FROM messages" +
                            where(file_) + " ORDER BY timestamp, id");
                if (st_->step()) return read(out);
                st_.reset();
                ++file_;
            }
            return false;
        }
        std::size_t size() const override { return size_; }

      private:
        std::string where(std::size_t file) const {
            if (topic_.empty()) return {};
            std::string ids;
            for (const auto& [key, c] : store_.conns_)
                if (key.first == file && c->topic == topic_)
                    ids += (ids.empty() ? "" : ",") + std::to_string(key.second);
            return " WHERE topic_id IN (" + (ids.empty() ? std::string("-1") : ids) + ")";
        }
        bool read(NativeMessage& out) {
            const Db& db = *store_.dbs_[file_];
            const auto c = store_.conns_.find({file_, st_->integer(0)});
            if (c == store_.conns_.end())
                throw BagError(db.path + ": a message of topic id " +
                                   std::to_string(st_->integer(0)) + " that 'topics' lacks",
                               db.path);
            const std::int64_t t = st_->integer(1), n = st_->integer(2);
            if (t < 0 || t / 1000000000 > 0xffffffffll)
                throw BagError(db.path + ": a message on " + c->second->topic + " with timestamp " +
                                   std::to_string(t) +
                                   " ns, not a time (before 1970 or after 2106)",
                               db.path);
            if (n > kMaxMessageBytes)
                throw BagError(db.path + ": a message on " + c->second->topic + " of " +
                                   std::to_string(n) + " bytes (kfd reads up to 256 MiB)",
                               db.path);
            const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(st_->get(), 3));
            out.connection = nullptr;
            out.ros2 = c->second.get();
            out.time_ns = t;
            out.time.fromNSec(static_cast<std::uint64_t>(t));
            out.bytes.assign(data, data + (data ? n : 0));
            return true;
        }

        Rosbag2Store& store_;
        std::string topic_;
        std::size_t size_ = 0, file_ = 0;
        std::unique_ptr<Statement> st_;
    };

    void readTopics(std::size_t i) {
        const Db& d = *dbs_[i];
        const bool hash = hasColumn(d, "topics", "type_description_hash");
        Statement s(d, std::string("SELECT id, name, type, serialization_format, "
                                   "offered_qos_profiles") +
                           (hash ? ", type_description_hash" : "") + " FROM topics");
        while (s.step()) {
            auto c = std::make_unique<Ros2Connection>();
            c->topic = s.text(1);
            c->type = s.text(2);
            c->encoding = s.text(3);
            c->offered_qos_profiles = s.text(4);
            if (hash) c->type_description_hash = s.text(5);
            conns_[{i, s.integer(0)}] = std::move(c);
        }
    }

    std::string path_, compression_;
    std::vector<std::unique_ptr<Db>> dbs_;
    std::map<std::pair<std::size_t, std::int64_t>, std::unique_ptr<Ros2Connection>> conns_;
};

// metadata.yaml: the storage, the files in order, the compression (refused: kfd reads
// uncompressed rosbag2 files; `ros2 bag convert` writes one).
std::vector<std::string> filesOf(const std::string& dir, std::string& storage) {
    const std::string meta = (fs::path(dir) / "metadata.yaml").string();
    YAML::Node info;
    try {
        info = YAML::LoadFile(meta)["rosbag2_bagfile_information"];
    } catch (const std::exception& e) {
        throw BagError(meta + ": not readable YAML (" + e.what() + ")", meta);
    }
    if (!info || !info.IsMap())
        throw BagError(meta + ": no 'rosbag2_bagfile_information' (not a rosbag2 metadata file)",
                       meta);
    try {
        storage = info["storage_identifier"] ? info["storage_identifier"].as<std::string>() : "";
        const std::string mode =
            info["compression_mode"] ? info["compression_mode"].as<std::string>() : "";
        if (!mode.empty() && mode != "NONE")
            throw BagError(meta + ": compressed rosbag2 (" + mode + " " +
                               info["compression_format"].as<std::string>("") +
                               "): kfd reads uncompressed bags; `ros2 bag decompress` or "
                               "`ros2 bag convert` writes one",
                           meta);
        std::vector<std::string> files;
        for (const auto& f : info["relative_file_paths"])
            files.push_back((fs::path(dir) / f.as<std::string>()).string());
        if (files.empty()) throw BagError(meta + ": lists no files (relative_file_paths)", meta);
        return files;
    } catch (const YAML::Exception& e) {
        throw BagError(meta + ": not a rosbag2 metadata file (" + e.what() + ")", meta);
    }
}

}  // namespace

std::unique_ptr<MessageStore> openRosbag2(const std::string& path) {
    std::error_code ec;
    if (!fs::is_directory(path, ec))
        return std::make_unique<Rosbag2Store>(path, std::vector{path}, "none");
    std::string storage;
    auto files = filesOf(path, storage);
    if (storage == "mcap") {
        if (files.size() != 1)
            throw BagError(path + ": a rosbag2 of " + std::to_string(files.size()) +
                               " MCAP files: kfd reads one (give it the .mcap file itself)",
                           path);
        return openMcap(files[0], false);
    }
    if (storage != "sqlite3" && !storage.empty())
        throw BagError(path + ": rosbag2 storage '" + storage + "' (kfd reads sqlite3 and mcap)",
                       path);
    for (const auto& f : files)
        if (!fs::is_regular_file(f, ec))
            throw BagError(path + ": metadata.yaml lists " + f + ", which is missing", path);
    return std::make_unique<Rosbag2Store>(path, std::move(files), "none");
}

}  // namespace kfd
