// libFuzzer target: the YAML configuration loader (kfd::loadYamlText: the pre-check, then
// MRPT's YAML parser, then the keys). kfd::ConfigError is an accepted outcome; anything else
// (a crash, a hang caught by -timeout, another exception) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "kfd/mrpt/config.h"
#include "kfd/pipeline/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        (void)kfd::loadYamlText(text, "fuzz.yaml");
    } catch (const kfd::Error&) {
    }
    return 0;
}
