#include "kfd/io/gz_output.h"

#include <mrpt/serialization/CArchive.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

namespace kfd {

// zlib's gzwrite buffer size (GZBUFSIZE): the same sizes give deflate the same calls, and so the
// same bytes as CFileGZOutputStream (gzopen/gzwrite/gzclose) at every level, stored blocks
// included.
constexpr unsigned kSize = 8192;

// The gzip stream as zlib's gzwrite (gz_write) and gz_comp run it, writing into an OutputFile.
struct GzOutputStream::Impl {
    OutputFile file;
    z_stream z{};
    bool deflating = false, finished = false;
    std::array<unsigned char, kSize> in{}, out{};
    unsigned char* pending = nullptr;  // the start of the output not yet written
    std::uint64_t position = 0;
    std::exception_ptr error;  // the first write failure, rethrown by every later call

    Impl(const std::filesystem::path& path, std::string name) : file(path, std::move(name)) {}

    [[noreturn]] void fail(const std::string& why) {
        throw WriteError("cannot write " + file.name() + ": " + why, file.name());
    }

    void writePending() {
        if (z.next_out > pending)
            file.write(pending, static_cast<std::size_t>(z.next_out - pending));
        pending = z.next_out;
    }

    // gz_comp: deflate until it produces no more output; the buffer is written when full, or
    // when flushing (Z_FINISH: once the stream ended).
    void compress(int flush) {
        int ret = Z_OK;
        unsigned have = 0;
        do {
            if (z.avail_out == 0 ||
                (flush != Z_NO_FLUSH && (flush != Z_FINISH || ret == Z_STREAM_END))) {
                writePending();
                if (z.avail_out == 0) {
                    z.next_out = out.data();
                    z.avail_out = kSize;
                    pending = out.data();
                }
            }
            have = z.avail_out;
            ret = ::deflate(&z, flush);
            if (ret == Z_STREAM_ERROR) fail("zlib error");
            have -= z.avail_out;
        } while (have);
        if (flush == Z_FINISH) writePending();
    }

    // gz_write: small writes are gathered in `in` (compressed when more comes than fits), large
    // ones compressed directly.
    void write(const unsigned char* buf, std::size_t len) {
        if (len < kSize) {
            while (len) {
                if (z.avail_in == 0) z.next_in = in.data();
                const auto have = static_cast<std::size_t>(z.next_in + z.avail_in - in.data());
                const std::size_t copy = std::min<std::size_t>(kSize - have, len);
                std::memcpy(in.data() + have, buf, copy);
                z.avail_in += static_cast<uInt>(copy);
                buf += copy;
                len -= copy;
                if (len) compress(Z_NO_FLUSH);
            }
        } else {
            if (z.avail_in) compress(Z_NO_FLUSH);
            z.next_in = const_cast<unsigned char*>(buf);
            while (len) {
                const std::size_t n = std::min<std::size_t>(len, std::numeric_limits<uInt>::max());
                z.avail_in = static_cast<uInt>(n);
                compress(Z_NO_FLUSH);
                len -= n;
            }
        }
    }
};

GzOutputStream::GzOutputStream(const std::filesystem::path& path, std::string name, int level)
    : impl_(std::make_unique<Impl>(path, std::move(name))) {
    Impl& d = *impl_;
    // As zlib's gzopen(path, "wbN"): gzip wrapping (15 + 16), memory level 8, default strategy.
    if (deflateInit2(&d.z, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
        d.fail("zlib cannot start (level " + std::to_string(level) + ")");
    d.deflating = true;
    d.z.next_out = d.out.data();
    d.z.avail_out = kSize;
    d.pending = d.out.data();
}

GzOutputStream::~GzOutputStream() {
    if (impl_->deflating) deflateEnd(&impl_->z);
}

const std::string& GzOutputStream::name() const { return impl_->file.name(); }

size_t GzOutputStream::Write(const void* buffer, size_t count) {
    Impl& d = *impl_;
    if (d.error) std::rethrow_exception(d.error);
    if (d.finished) d.fail("the gzip stream is already closed");
    try {
        d.write(static_cast<const unsigned char*>(buffer), count);
    } catch (const WriteError&) {
        d.error = std::current_exception();
        throw;
    }
    d.position += count;
    return count;
}

void GzOutputStream::write(const mrpt::serialization::CSerializable& obj) {
    try {
        auto archive = mrpt::serialization::archiveFrom(*this);
        archive << obj;
    } catch (...) {  // MRPT wraps what Write threw in its own exception: ours, as it was
        if (impl_->error) std::rethrow_exception(impl_->error);
        throw;
    }
}

void GzOutputStream::close() {
    Impl& d = *impl_;
    if (d.error) std::rethrow_exception(d.error);
    if (d.finished) return;
    try {
        d.compress(Z_FINISH);  // the rest and the trailer (CRC-32, length)
        d.finished = true;
        deflateEnd(&d.z);
        d.deflating = false;
        d.file.close();  // flush, fsync, size and the trailer read back
    } catch (const WriteError&) {
        d.error = std::current_exception();
        throw;
    }
}

size_t GzOutputStream::Read(void*, size_t) { impl_->fail("the gzip output is write-only"); }

uint64_t GzOutputStream::Seek(int64_t, TSeekOrigin) { impl_->fail("the gzip output cannot seek"); }

uint64_t GzOutputStream::getTotalBytesCount() const { return impl_->position; }
uint64_t GzOutputStream::getPosition() const { return impl_->position; }
std::string GzOutputStream::getStreamDescription() const {
    return "kfd::GzOutputStream " + impl_->file.name();
}

}  // namespace kfd
