// libFuzzer target: the .ini configuration loader (kfd::loadConfigFile on a .ini file with
// arbitrary text). kfd::ConfigError is an accepted outcome; anything else is a finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include "kfd/mrpt/config.h"
#include "kfd/pipeline/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const std::string path = "/tmp/kfd-fuzz-ini-" + std::to_string(getpid()) + ".ini";
    {
        std::ofstream f(path, std::ios::binary | std::ios::trunc);
        f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    }
    try {
        (void)kfd::loadConfigFile(path);
    } catch (const kfd::Error&) {
    }
    return 0;
}
