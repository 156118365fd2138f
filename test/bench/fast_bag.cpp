// kfd_bench_fast_bag OUT.bag COMPRESSION SECONDS [SCAN_HZ BEAMS FOV_DEG [NOISE_M]]: writes a
// bag like a fast scanner's (/scan at 35 Hz with 1079 beams over 172 degrees, or SCAN_HZ, BEAMS and
// FOV_DEG and uniform range noise of NOISE_M, beside multi-echo scans, an IMU at 200 Hz, odometry
// and /tf at 50 Hz; kfd::test::writeFastScannerBag) with chunks of COMPRESSION (none, bz2 or lz4):
// the bag of several high-rate topics of docs/CHANGELOG.md's "Reading bags (issue 23)", and with
// `40 1081 270 0.01` the simulated 40 Hz scanner of "kfd_node live (issue 24)".
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "test_bags.h"

int main(int argc, char** argv) {
    if (argc != 4 && argc != 7 && argc != 8) {
        std::fprintf(stderr,
                     "usage: kfd_bench_fast_bag OUT.bag none|bz2|lz4 SECONDS [SCAN_HZ BEAMS "
                     "FOV_DEG [NOISE_M]]\n");
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
    kfd::test::FastScanner scanner;
    if (argc >= 7) {
        scanner.scan_hz = std::atof(argv[4]);
        scanner.beams = static_cast<std::size_t>(std::atol(argv[5]));
        scanner.fov = std::atof(argv[6]) * M_PI / 180.0;
        if (argc == 8) scanner.noise = std::atof(argv[7]);
        if (!(scanner.scan_hz > 0) || scanner.beams < 2 || !(scanner.fov > 0)) {
            std::fprintf(stderr,
                         "kfd_bench_fast_bag: SCAN_HZ, BEAMS (>= 2) and FOV_DEG must be "
                         "positive\n");
            return 2;
        }
    }
    try {
        kfd::test::writeFastScannerBag(argv[1], compression, false, std::atof(argv[3]), scanner);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd_bench_fast_bag: %s\n", e.what());
        return 1;
    }
    return 0;
}
