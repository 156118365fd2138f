#include "kfd/mrpt/rawlog_source.h"

#include <mrpt/io/CStream.h>
#include <mrpt/serialization/CArchive.h>
#include <zlib.h>

#include <filesystem>

namespace kfd {
namespace {

namespace fs = std::filesystem;

// MRPT nests exception texts ("==== MRPT exception ==== Message: ..."); keep the innermost
// message line, which says what actually failed.
std::string lastMessage(const std::string& what) {
    const auto pos = what.rfind("Message:");
    if (pos == std::string::npos) return what.substr(0, what.find('\n'));
    std::string line = what.substr(pos + 8, what.find('\n', pos) - pos - 8);
    const auto b = line.find_first_not_of(' ');
    return b == std::string::npos ? line : line.substr(b);
}

// mrpt::io::CFileGZInputStream's reading (gzopen "rb", gzread, gztell: plain files are read
// as they are), keeping zlib's error state so that a gzip stream cut short is told apart from
// a complete one.
class GzReader : public mrpt::io::CStream {
  public:
    explicit GzReader(const std::string& path) : file_(gzopen(path.c_str(), "rb")) {
        std::error_code ec;
        const auto n = fs::file_size(path, ec);
        size_ = ec ? 0 : n;
    }
    ~GzReader() override {
        if (file_) gzclose(file_);
    }
    GzReader(const GzReader&) = delete;
    GzReader& operator=(const GzReader&) = delete;
    bool isOpen() const { return file_ != nullptr; }

    size_t Read(void* buf, size_t count) override {
        const int n = gzread(file_, buf, static_cast<unsigned>(count));
        if (n < 0) {
            failed_ = true;
            return 0;
        }
        return static_cast<size_t>(n);
    }
    size_t Write(const void*, size_t) override {
        throw RawlogError("a rawlog source is read only");
    }
    uint64_t Seek(int64_t, TSeekOrigin) override {
        throw RawlogError("a rawlog source cannot seek");
    }
    uint64_t getTotalBytesCount() const override { return size_; }
    uint64_t getPosition() const override { return static_cast<uint64_t>(gztell(file_)); }
    std::string getStreamDescription() const override { return "kfd::RawlogSource"; }

    // After the data ended: true when zlib failed or the gzip stream stopped before its end.
    bool cutShort() const {
        int err = Z_OK;
        gzerror(file_, &err);
        return failed_ || err == Z_BUF_ERROR || err == Z_DATA_ERROR;
    }

  private:
    gzFile file_;
    std::uint64_t size_ = 0;
    bool failed_ = false;
};

}  // namespace

struct RawlogSource::Impl {
    std::string path;
    GzReader in;
    mrpt::serialization::CArchiveStreamBase<mrpt::io::CStream> arch{in};
    OdometryTracker odometry;
    mrpt::serialization::CSerializable::Ptr lookahead;  // read after a lone action
    bool ended = false;
    std::size_t objects = 0, entries = 0;

    explicit Impl(const std::string& p) : path(p), in(p) {}

    // The next object, or nullptr at a clean end of file. Null objects stored in the file are
    // skipped (and not counted).
    mrpt::serialization::CSerializable::Ptr read() {
        if (lookahead) return std::move(lookahead);
        mrpt::serialization::CSerializable::Ptr obj;
        while (!obj && !ended) {
            try {
                obj = arch.ReadObject();
            } catch (const mrpt::serialization::CExceptionEOF&) {
                ended = true;
                if (in.cutShort()) throw error("the gzip stream ends early");
            } catch (const std::exception& e) {
                ended = true;
                throw error(lastMessage(e.what()));
            }
        }
        if (obj) ++objects;
        return obj;
    }

    RawlogError error(const std::string& what) const {
        return RawlogError(
            "cannot read object #" + std::to_string(objects) + " of " + path +
                (objects == 0 ? " (is it an MRPT rawlog?): " : " (truncated or corrupt file?): ") +
                what,
            path);
    }
};

RawlogSource::RawlogSource(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw RawlogError("input rawlog not found: " + path, path);
    impl_ = std::make_unique<Impl>(path);
    if (!impl_->in.isOpen()) throw RawlogError("cannot open the input rawlog: " + path, path);
    if (impl_->in.getTotalBytesCount() == 0) throw RawlogError("the input is empty: " + path, path);
}

RawlogSource::~RawlogSource() = default;

bool RawlogSource::next(SourceEntry& e) {
    using mrpt::obs::CActionCollection;
    using mrpt::obs::CObservation;
    using mrpt::obs::CSensoryFrame;
    Impl& m = *impl_;
    auto obj = m.read();
    if (!obj) return false;
    e = SourceEntry();
    if (auto acts = std::dynamic_pointer_cast<CActionCollection>(obj)) {
        e.action = acts;
        m.odometry.onAction(*acts);
        auto following = m.read();
        if (auto sf = std::dynamic_pointer_cast<CSensoryFrame>(following)) {
            e.kind = SourceEntry::Kind::Frame;
            e.frame = sf;
        } else {
            e.kind = SourceEntry::Kind::Action;
            m.lookahead = std::move(following);
        }
    } else if (auto sf = std::dynamic_pointer_cast<CSensoryFrame>(obj)) {
        e.kind = SourceEntry::Kind::Frame;
        e.frame = sf;
    } else if (auto o = std::dynamic_pointer_cast<CObservation>(obj)) {
        e.kind = SourceEntry::Kind::Observation;
        e.observation = o;
        m.odometry.onObservation(*o);
    } else {
        e.kind = SourceEntry::Kind::Other;
        e.other = std::move(obj);
    }
    e.odometry = m.odometry.current();
    e.index = m.entries++;
    e.objects_read = m.objects - (m.lookahead ? 1 : 0);
    return true;
}

const std::string& RawlogSource::path() const { return impl_->path; }
std::uint64_t RawlogSource::bytesRead() const { return impl_->in.getPosition(); }
std::uint64_t RawlogSource::bytesTotal() const { return impl_->in.getTotalBytesCount(); }

}  // namespace kfd
