#include "kfd/io/png_output.h"

#include <png.h>
#include <zlib.h>

#include <csetjmp>
#include <exception>
#include <vector>

#include "kfd/os/output_paths.h"

namespace kfd {
namespace {

// What libpng's callbacks need: the file, and why libpng stopped.
struct PngSink {
    OutputFile* file = nullptr;
    std::exception_ptr write_error;  // the OutputFile's WriteError
    std::string png_error;           // libpng's own message
};

// libpng's callbacks are C: no exception may cross them. A failed write is kept and libpng
// is stopped through png_error (a longjmp back to writePng's setjmp, through C frames only).
void pngWrite(png_structp png, png_bytep data, png_size_t size) {
    auto* sink = static_cast<PngSink*>(png_get_io_ptr(png));
    bool failed = false;
    try {
        sink->file->write(data, size);
    } catch (...) {
        sink->write_error = std::current_exception();
        failed = true;
    }
    if (failed) png_error(png, "write failed");
}

void pngFlush(png_structp) {}

void pngError(png_structp png, png_const_charp message) {
    auto* sink = static_cast<PngSink*>(png_get_error_ptr(png));
    if (sink->png_error.empty()) sink->png_error = message ? message : "libpng error";
    png_longjmp(png, 1);
}

void pngWarning(png_structp, png_const_charp) {}  // never printed

// The encoding, apart from anything with a destructor (setjmp/longjmp in this frame).
bool encode(png_structp png, png_infop info, PngSink& sink, png_uint_32 width, png_uint_32 height,
            int color_type, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_write_fn(png, &sink, pngWrite, pngFlush);
    // OpenCV's PngEncoder without a compression parameter (what CImage::saveToFile asks for).
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_compression_level(png, Z_BEST_SPEED);
    png_set_compression_strategy(png, Z_RLE);
    png_set_IHDR(png, info, width, height, 8, color_type, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_set_bgr(png);  // MRPT (OpenCV) holds BGR
    png_write_image(png, rows);
    png_write_end(png, info);
    return true;
}

}  // namespace

void writePng(const mrpt::img::CImage& image, const std::filesystem::path& path,
              const std::string& name) {
    auto refuse = [&](const std::string& why) -> WriteError {
        return WriteError("cannot write " + name + ": " + why, name);
    };
    const std::size_t width = image.getWidth(), height = image.getHeight();
    const int channels = static_cast<int>(image.getChannelCount());
    if (width == 0 || height == 0) throw refuse("the image is empty");
    if (image.getPixelDepth() != mrpt::img::PixelDepth::D8U)
        throw refuse("only 8-bit images are written as PNG");
    const int color_type = channels == 1   ? PNG_COLOR_TYPE_GRAY
                           : channels == 3 ? PNG_COLOR_TYPE_RGB
                           : channels == 4 ? PNG_COLOR_TYPE_RGBA
                                           : -1;
    if (color_type < 0) throw refuse("an image of " + std::to_string(channels) + " channels");
    std::vector<png_bytep> rows(height);
    for (std::size_t y = 0; y < height; ++y)
        rows[y] = const_cast<png_bytep>(image.ptrLine<png_byte>(static_cast<unsigned>(y)));

    OutputFile file(path, name);
    PngSink sink;
    sink.file = &file;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, pngError, pngWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        throw refuse("libpng cannot start");
    }
    const bool ok = encode(png, info, sink, static_cast<png_uint_32>(width),
                           static_cast<png_uint_32>(height), color_type, rows.data());
    png_destroy_write_struct(&png, &info);
    if (sink.write_error) std::rethrow_exception(sink.write_error);
    if (!ok) throw refuse("libpng: " + sink.png_error);
    file.close();  // flush, fsync, size and the IEND chunk read back
}

}  // namespace kfd
