// The bag fuzz targets' one input: arbitrary bytes written to a temporary file of the given
// extension, read through BagSource::next() until the end, then listed. kfd::Error (BagError,
// SourceError) is an accepted outcome; anything else is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

#include <rosbag/bag.h>

#include "kfd/io/bag_source.h"
#include "kfd/pipeline/error.h"

// Inputs of any format reach ROS 1's bag reader (the format is told by content). Every
// rosbag::Bag loads rosbag_storage's encryptor plugin through class_loader, and the last
// one destroyed unloads it again: dlopen + dlclose of a library whose deps reach ~180 others
// was most of an execution (perf: __cxa_finalize 36 %, symbol lookup 17 %; 21 exec/s). One Bag
// kept for the whole process keeps the plugin loaded, so each input's Bags only add an owner.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    static rosbag::Bag* const keep_plugin_loaded = new rosbag::Bag;
    (void)keep_plugin_loaded;
    return 0;
}

inline int fuzzBagSource(const std::uint8_t* data, std::size_t size, const char* ext) {
    static const std::string path =
        "/tmp/kfd-fuzz-" + std::to_string(getpid()) + "-bag" + std::string(ext);
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
