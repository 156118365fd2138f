#include "kfd/mrpt/rawlog_source.h"

#include <mrpt/io/CStream.h>
#include <mrpt/serialization/CArchive.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include "kfd/mrpt/allocation_limit.h"

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

// Reads a plain or gzip file (told apart by the gzip magic bytes) through zlib's inflate, so
// that the end of the gzip stream is checked: inflate (windowBits 15 + 16) verifies the
// trailer's CRC-32 and ISIZE (Z_DATA_ERROR on a mismatch), a trailer that never came means
// Z_STREAM_END never came, and bytes after the stream must be another gzip member.
class GzReader : public mrpt::io::CStream {
  public:
    explicit GzReader(const std::string& path) : file_(std::fopen(path.c_str(), "rb")) {
        std::error_code ec;
        const auto n = fs::file_size(path, ec);
        size_ = ec ? 0 : n;
        if (!file_) return;
        fill();
        gzip_ = avail_ >= 2 && in_[0] == 0x1f && in_[1] == 0x8b;
        if (gzip_ && inflateInit2(&z_, 15 + 16) != Z_OK) {
            std::fclose(file_);
            file_ = nullptr;
        }
    }
    ~GzReader() override {
        if (gzip_) inflateEnd(&z_);
        if (file_) std::fclose(file_);
    }
    GzReader(const GzReader&) = delete;
    GzReader& operator=(const GzReader&) = delete;
    bool isOpen() const { return file_ != nullptr; }
    bool isGzip() const { return gzip_; }
    // The size getTotalBytesCount() reports: the decoded size once it is known.
    void setTotal(std::uint64_t decoded) { size_ = decoded; }

    size_t Read(void* buf, size_t count) override {
        if (error_.size() || count == 0) return 0;
        auto* out = static_cast<unsigned char*>(buf);
        std::size_t done = 0;
        if (!gzip_) {
            while (done < count) {
                if (avail_ == 0 && !fill()) break;
                const std::size_t n = std::min(count - done, avail_);
                std::memcpy(out + done, in_.data() + pos_, n);
                pos_ += n;
                avail_ -= n;
                done += n;
            }
            position_ += done;
            return done;
        }
        while (done < count) {
            if (stream_end_) {  // another gzip member, or the end of the file
                if (avail_ == 0 && !fill()) break;
                if (avail_ < 2 && !fill()) {
                    error_ = "garbage after the gzip stream";
                    break;
                }
                if (in_[pos_] != 0x1f || in_[pos_ + 1] != 0x8b) {
                    error_ = "garbage after the gzip stream";
                    break;
                }
                inflateReset(&z_);
                stream_end_ = false;
            }
            if (avail_ == 0 && !fill()) {
                error_ = "the gzip stream ends early (no trailer)";
                break;
            }
            z_.next_in = in_.data() + pos_;
            z_.avail_in = static_cast<uInt>(avail_);
            z_.next_out = out + done;
            z_.avail_out = static_cast<uInt>(std::min<std::size_t>(count - done, 1u << 30));
            const int rc = inflate(&z_, Z_NO_FLUSH);
            const std::size_t used = avail_ - z_.avail_in;
            pos_ += used;
            avail_ -= used;
            const bool progressed = used > 0 || z_.next_out != out + done;
            done = static_cast<std::size_t>(z_.next_out - out);
            if (!progressed && rc == Z_BUF_ERROR && !fill()) {
                error_ = "the gzip stream ends early (no trailer)";
                break;
            }
            if (rc == Z_STREAM_END) {
                stream_end_ = true;
            } else if (rc != Z_OK && rc != Z_BUF_ERROR) {
                error_ =
                    std::string("corrupt gzip data (") + (z_.msg ? z_.msg : "zlib error") + ")";
                break;
            }
        }
        position_ += done;
        return done;
    }
    size_t Write(const void*, size_t) override {
        throw RawlogError("a rawlog source is read only");
    }
    uint64_t Seek(int64_t, TSeekOrigin) override {
        throw RawlogError("a rawlog source cannot seek");
    }
    uint64_t getTotalBytesCount() const override { return size_; }
    uint64_t getPosition() const override { return position_; }  // decoded bytes
    std::string getStreamDescription() const override { return "kfd::RawlogSource"; }

    const std::string& error() const { return error_; }

    // After the data ended: why the stream is broken (read error, corrupt or cut-short gzip,
    // garbage after it), or empty for a clean end.
    std::string failure() {
        if (error_.empty() && gzip_ && !stream_end_) {
            unsigned char probe;
            Read(&probe, 1);  // reach the trailer
            if (error_.empty() && !stream_end_) error_ = "the gzip stream ends early";
        }
        if (error_.empty() && gzip_) {  // nothing may follow the last member
            if (avail_ > 0 || fill()) error_ = "garbage after the gzip stream";
        }
        return error_;
    }

  private:
    // Reads more of the file into in_ when it is used up; false at its end or on a read error.
    bool fill() {
        if (avail_ > 0) {
            if (pos_ > 0) {
                std::memmove(in_.data(), in_.data() + pos_, avail_);
                pos_ = 0;
            }
            if (avail_ == in_.size()) return true;
        } else {
            pos_ = 0;
        }
        const std::size_t n = std::fread(in_.data() + avail_, 1, in_.size() - avail_, file_);
        if (n == 0 && std::ferror(file_)) error_ = "read error";
        avail_ += n;
        return n > 0;
    }

    std::FILE* file_;
    std::uint64_t size_ = 0, position_ = 0;
    std::array<unsigned char, 1 << 16> in_{};
    std::size_t pos_ = 0, avail_ = 0;
    bool gzip_ = false, stream_end_ = false;
    z_stream z_{};
    std::string error_;
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
                // No allocation larger than the data left (allocation_limit.h).
                const ScopedAllocationLimit limit(static_cast<std::size_t>(std::min<std::uint64_t>(
                                                      bytesLeft(), SIZE_MAX - kAllocationSlack)) +
                                                  kAllocationSlack);
                obj = arch.ReadObject();
            } catch (const mrpt::serialization::CExceptionEOF&) {
                ended = true;
                if (const std::string f = in.failure(); !f.empty()) throw error(f);
            } catch (const std::bad_alloc&) {
                ended = true;
                throw error("an object claims more memory than the " + std::to_string(bytesLeft()) +
                            " bytes left in the file (a corrupt length field)");
            } catch (const std::exception& e) {
                ended = true;
                if (!in.error().empty()) throw error(in.error());  // the gzip layer knows why
                throw error(lastMessage(e.what()));
            }
        }
        if (obj) ++objects;
        return obj;
    }

    // Decoded bytes not read yet.
    std::uint64_t bytesLeft() const {
        return in.getTotalBytesCount() - std::min(in.getPosition(), in.getTotalBytesCount());
    }

    RawlogError error(const std::string& what) const {
        return RawlogError(
            "cannot read object #" + std::to_string(objects) + " of " + path +
                (objects == 0 ? " (is it an MRPT rawlog?): " : " (truncated or corrupt file?): ") +
                what,
            path);
    }
};

namespace {
// Decodes the whole file once; returns its decoded size, or throws RawlogError naming the
// file and the reason.
std::uint64_t decodeAll(const std::string& path) {
    GzReader in(path);
    if (!in.isOpen()) throw RawlogError("cannot open " + path, path);
    std::vector<char> buf(1 << 16);
    std::uint64_t total = 0;
    while (const std::size_t n = in.Read(buf.data(), buf.size())) total += n;
    if (const std::string f = in.failure(); !f.empty())
        throw RawlogError(path + ": " + f + " (truncated or corrupt file?)", path);
    return total;
}
}  // namespace

void checkGzipIntegrity(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw RawlogError("file not found: " + path, path);
    decodeAll(path);
}

RawlogSource::RawlogSource(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw RawlogError("input rawlog not found: " + path, path);
    impl_ = std::make_unique<Impl>(path);
    if (!impl_->in.isOpen()) throw RawlogError("cannot open the input rawlog: " + path, path);
    if (impl_->in.getTotalBytesCount() == 0) throw RawlogError("the input is empty: " + path, path);
    // A gzip file is decoded once before any object is read: damaged compressed data decodes
    // to garbage whose length fields MRPT's deserialisers trust (a 12 kB file found by
    // fuzz_rawlog made them allocate 2.7 GB), and a cut or corrupt file then fails before
    // anything is written. It also gives the decoded size, which bytesRead() counts in.
    if (impl_->in.isGzip()) impl_->in.setTotal(decodeAll(path));
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
