// libFuzzer target: the ROS bag source fed arbitrary bytes (written to a temporary .bag): the
// structure check, then BagSource::next() until the end, and the listing. kfd::Error (BagError,
// SourceError) is an accepted outcome; anything else (a crash in kfd or in rosbag_storage on a
// file the structure check let through) is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_bag_source.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return fuzzBagSource(data, size, ".bag");
}
