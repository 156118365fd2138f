// kfd_bench_fast_bag OUT.bag COMPRESSION SECONDS: writes a bag like a fast scanner's (/scan at
// 35 Hz with 1079 beams beside multi-echo scans, an IMU at 200 Hz, odometry and /tf at 50 Hz;
// kfd::test::writeFastScannerBag) with chunks of COMPRESSION (none, bz2 or lz4): the bag of
// several high-rate topics of docs/RESULTS.md's "Reading bags (issue 23)".
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "test_bags.h"

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: kfd_bench_fast_bag OUT.bag none|bz2|lz4 SECONDS\n");
        return 2;
    }
    const std::string c = argv[2];
    const auto compression = c == "bz2"   ? rosbag::compression::BZ2
                             : c == "lz4" ? rosbag::compression::LZ4
                                          : rosbag::compression::Uncompressed;
    if (c != "none" && c != "bz2" && c != "lz4") {
        std::fprintf(stderr, "kfd_bench_fast_bag: unknown compression '%s'\n", argv[2]);
        return 2;
    }
    try {
        kfd::test::writeFastScannerBag(argv[1], compression, false, std::atof(argv[3]));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd_bench_fast_bag: %s\n", e.what());
        return 1;
    }
    return 0;
}
