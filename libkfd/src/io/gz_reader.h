// A plain or gzip file read through zlib with the end of the stream checked (private to
// libkfd: the rawlog and CARMEN sources read through it).
#pragma once

#include <mrpt/io/CStream.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "kfd/io/source.h"

namespace kfd::detail {

// A misuse of the reader (a write or a seek): it only reads forward. A SourceError, so that
// the sources' callers catch it like their own errors.
class GzError : public SourceError {
  public:
    using SourceError::SourceError;
};

// Reads a plain or gzip file (told apart by the gzip magic bytes) through zlib's inflate, so
// that the end of the gzip stream is checked: inflate (windowBits 15 + 16) verifies the
// trailer's CRC-32 and ISIZE (Z_DATA_ERROR on a mismatch), a trailer that never came means
// Z_STREAM_END never came, and bytes after the stream must be another gzip member.
class GzReader : public mrpt::io::CStream {
  public:
    explicit GzReader(const std::string& path) : file_(std::fopen(path.c_str(), "rb")) {
        std::error_code ec;
        const auto n = std::filesystem::file_size(path, ec);
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
    size_t Write(const void*, size_t) override { throw GzError("a rawlog source is read only"); }
    uint64_t Seek(int64_t, TSeekOrigin) override { throw GzError("a rawlog source cannot seek"); }
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

}  // namespace kfd::detail
