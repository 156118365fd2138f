// libFuzzer target: the bag source fed arbitrary bytes as a rosbag2 sqlite3 file (sqlite3,
// rosbag2's tables, CDR messages) (fuzz_bag_source.h).
#include <cstddef>
#include <cstdint>

#include "fuzz_bag_source.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return fuzzBagSource(data, size, ".db3");
}
