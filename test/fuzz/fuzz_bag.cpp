// libFuzzer target: the ROS bag source fed arbitrary bytes (written to a temporary .bag): the
// structure check, then BagSource::next() until the end, and the listing. kfd::Error (BagError,
// SourceError) is an accepted outcome; anything else (a crash in kfd or in rosbag_storage on a
// file the structure check let through) is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "kfd/core/error.h"
#include "kfd/mrpt/bag_source.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = "/tmp/kfd-fuzz-bag-" + std::to_string(getpid()) + ".bag";
    {
        std::ofstream f(path, std::ios::binary | std::ios::trunc);
        f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    }
    try {
        kfd::BagSource source(path);
        kfd::SourceEntry e;
        for (int n = 0; n < 10000 && source.next(e); ++n) {
        }
    } catch (const kfd::Error&) {
    }
    try {
        (void)kfd::listBag(path);
    } catch (const kfd::Error&) {
    }
    return 0;
}
