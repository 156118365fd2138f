// libFuzzer target: the rawlog source fed arbitrary bytes (written to a temporary file, plain
// or gzip as the bytes say), read with RawlogSource::next() until the end.
// kfd::Error (RawlogError, SourceError) is an accepted outcome; anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "kfd/io/rawlog_source.h"
#include "kfd/pipeline/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = "/tmp/kfd-fuzz-rawlog-" + std::to_string(getpid()) + ".rawlog";
    {
        std::ofstream f(path, std::ios::binary | std::ios::trunc);
        f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    }
    try {
        kfd::RawlogSource source(path);
        kfd::SourceEntry e;
        for (int n = 0; n < 10000 && source.next(e); ++n) {
        }
    } catch (const kfd::Error&) {
    }
    return 0;
}
