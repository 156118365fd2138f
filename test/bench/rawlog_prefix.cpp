// kfd_bench_rawlog_prefix IN OUT PERCENT: writes the first PERCENT % of IN's top-level objects
// to OUT (gzip), so kfd-filter's peak memory can be measured on logs of growing size that are
// cut at object boundaries. Used by scripts/bench/bench.sh.
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/registerAllClasses.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>

#include "kfd/io/rawlog_source.h"

namespace {

std::size_t countObjects(const std::string& path) {
    kfd::RawlogSource source(path);
    kfd::SourceEntry e;
    std::size_t n = 0;
    while (source.next(e)) n = e.objects_read;
    return n;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: kfd_bench_rawlog_prefix IN.rawlog OUT.rawlog PERCENT\n");
        return 2;
    }
    const std::string input = argv[1], output = argv[2];
    const double percent = std::atof(argv[3]);
    if (!(percent > 0.0 && percent <= 100.0)) {
        std::fprintf(stderr, "kfd_bench_rawlog_prefix: PERCENT must be in (0, 100]\n");
        return 2;
    }
    // Loads and registers every observation/action class (nothing else here references them).
    mrpt::obs::registerAllClasses_mrpt_obs();
    try {
        const std::size_t total = countObjects(input);
        const auto keep = static_cast<std::size_t>(std::ceil(total * percent / 100.0));
        kfd::RawlogSource source(input);
        mrpt::io::CFileGZOutputStream out;
        if (!out.open(output, 1)) throw std::runtime_error("cannot write " + output);
        auto out_arch = mrpt::serialization::archiveFrom(out);
        std::size_t written = 0;
        kfd::SourceEntry e;
        while (written < keep && source.next(e))
            e.forEachObject([&](const auto& obj) {
                if (written < keep) out_arch << *obj;
                ++written;
            });
        std::printf("%s: %zu of %zu objects\n", output.c_str(), keep, total);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd_bench_rawlog_prefix: %s\n", e.what());
        return 1;
    }
    return 0;
}
