// libFuzzer target: the ROS bag source fed arbitrary bytes (written to a temporary .bag): the
// structure check, then BagSource::next() until the end, and the listing. kfd::Error (BagError,
// SourceError) is an accepted outcome; anything else (a crash in kfd or in rosbag_storage on a
// file the structure check let through) is a finding.
#include <cstddef>
#include <cstdint>

#include <rosbag/bag.h>

#include "fuzz_bag_source.h"

// Every rosbag::Bag loads rosbag_storage's encryptor plugin through class_loader, and the last
// one destroyed unloads it again: dlopen + dlclose of a library whose deps reach ~180 others
// was most of an execution (perf: __cxa_finalize 36 %, symbol lookup 17 %; 21 exec/s). One Bag
// kept for the whole process keeps the plugin loaded, so each input's Bags only add an owner.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    static rosbag::Bag* const keep_plugin_loaded = new rosbag::Bag;
    (void)keep_plugin_loaded;
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return fuzzBagSource(data, size, ".bag");
}
