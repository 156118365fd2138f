#include "kfd/mrpt/gz_output.h"

#include <mrpt/serialization/CArchive.h>
#include <zlib.h>

#include <array>
#include <optional>

namespace kfd {

struct GzOutputStream::Impl {
    OutputFile file;
    z_stream z{};
    bool deflating = false, finished = false;
    std::string input;                         // uncompressed bytes not yet deflated
    std::array<unsigned char, 1 << 16> out{};  // deflate's output
    std::uint64_t position = 0;
    std::exception_ptr error;  // the first write failure, rethrown by every later call

    Impl(const std::filesystem::path& path, std::string name) : file(path, std::move(name)) {}

    [[noreturn]] void fail(const std::string& why) {
        throw WriteError("cannot write " + file.name() + ": " + why, file.name());
    }

    // Deflates `input` (all of it) with `flush` and writes what comes out.
    void deflateInput(int flush) {
        z.next_in = reinterpret_cast<Bytef*>(input.data());
        z.avail_in = static_cast<uInt>(input.size());
        int rc = Z_OK;
        do {
            z.next_out = out.data();
            z.avail_out = static_cast<uInt>(out.size());
            rc = ::deflate(&z, flush);
            if (rc == Z_STREAM_ERROR) fail("zlib error");
            const std::size_t n = out.size() - z.avail_out;
            if (n) file.write(out.data(), n);
        } while (z.avail_out == 0 || (flush == Z_FINISH && rc != Z_STREAM_END));
        input.clear();
    }
};

namespace {
constexpr std::size_t kInputChunk = 1 << 16;
}  // namespace

GzOutputStream::GzOutputStream(const std::filesystem::path& path, std::string name, int level)
    : impl_(std::make_unique<Impl>(path, std::move(name))) {
    // As zlib's gzopen(path, "wbN"): gzip wrapping (15 + 16), memory level 8, default strategy.
    if (deflateInit2(&impl_->z, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
        impl_->fail("zlib cannot start (level " + std::to_string(level) + ")");
    impl_->deflating = true;
    impl_->input.reserve(kInputChunk);
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
        d.input.append(static_cast<const char*>(buffer), count);
        if (d.input.size() >= kInputChunk) d.deflateInput(Z_NO_FLUSH);
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
        d.deflateInput(Z_FINISH);  // the rest and the trailer (CRC-32, length)
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
