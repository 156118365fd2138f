// PNG images written with every error checked (instead of CImage::saveToFile, which returns
// false without a reason and lets libpng print "libpng error: Write Error" on stderr).
#pragma once

#include <mrpt/img/CImage.h>

#include <filesystem>
#include <string>

namespace kfd {

/// Writes `image` (8-bit grey, BGR or BGRA, as MRPT holds it) as a PNG at `path` through
/// libpng into kfd's checked OutputFile: the same bytes as CImage::saveToFile (OpenCV's PNG
/// encoder settings: SUB filter, zlib level 1, RLE strategy), every write, the fsync and the
/// close checked, the IEND chunk read back. libpng's own messages are kept off stderr. Throws
/// WriteError naming `name` (the file users know) and the reason: "cannot write map.png: No
/// space left on device"; an image kfd cannot encode (empty, other depth) is a WriteError too.
void writePng(const mrpt::img::CImage& image, const std::filesystem::path& path,
              const std::string& name);

}  // namespace kfd
