// libFuzzer target: the bag source fed arbitrary bytes as an MCAP file (kfd's own reader: records,
// chunks in lz4 or zstd, CDR messages) (fuzz_bag_source.h).
#include <cstddef>
#include <cstdint>

#include "fuzz_bag_source.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return fuzzBagSource(data, size, ".mcap");
}
