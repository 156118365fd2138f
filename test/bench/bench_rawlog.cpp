// kfd_bench_rawlog: kfd-filter's throughput on a large rawlog against the I/O limit.
//
//   BM_ParseRawlog   reads every object (kfd::RawlogSource: MRPT's CArchive over zlib) and
//                    does nothing else: the I/O limit;
//   BM_CopyRawlog    reads every object and writes it unchanged (gzip level 1, as kfd-filter);
//   BM_FilterRawlog  kfd::RawlogFilter::run, the whole of kfd-filter (read, filter, write),
//                    arg 0: kfd's defaults (= kfd-filter without -c = share/kfd/default.ini),
//                    1: the paper's method (share/kfd/paper-mit-0.752.ini), 2: kfd's defaults
//                    with an uncompressed output (kfd-filter --compress 0).
//
// Input: $KFD_BENCH_RAWLOG, or KFD_DATASETS_DIR/mit-killian/mit-killian.rawlog (17480 scans).
// When it is missing every benchmark is skipped with a message.
#include <benchmark/benchmark.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/registerAllClasses.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include <unistd.h>

#include "kfd/io/rawlog_filter.h"
#include "kfd/io/rawlog_source.h"
#include "kfd/mrpt/config.h"

#ifndef KFD_DATASETS_DIR
#define KFD_DATASETS_DIR "../shared/datasets"
#endif
#ifndef KFD_SOURCE_DIR
#define KFD_SOURCE_DIR "."
#endif

namespace {

namespace fs = std::filesystem;

std::string inputPath() {
    if (const char* env = std::getenv("KFD_BENCH_RAWLOG")) return env;
    return std::string(KFD_DATASETS_DIR) + "/mit-killian/mit-killian.rawlog";
}

bool haveInput(benchmark::State& state) {
    std::error_code ec;
    if (fs::is_regular_file(inputPath(), ec)) return true;
    const std::string msg =
        "rawlog not found: " + inputPath() + " (set KFD_DATASETS_DIR or KFD_BENCH_RAWLOG); skipped";
    state.SkipWithError(msg.c_str());
    return false;
}

// A scratch output next to the other temporary files, removed at the end.
struct TempOutput {
    fs::path path =
        fs::temp_directory_path() / ("kfd_bench_rawlog_" + std::to_string(::getpid()) + ".rawlog");
    ~TempOutput() {
        std::error_code ec;
        fs::remove(path, ec);
    }
};

void BM_ParseRawlog(benchmark::State& state) {
    if (!haveInput(state)) return;
    mrpt::obs::registerAllClasses_mrpt_obs();  // what kfd's own classes would load anyway
    std::size_t objects = 0;
    for (auto _ : state) {
        kfd::RawlogSource source(inputPath());
        kfd::SourceEntry e;
        objects = 0;
        while (source.next(e)) {
            benchmark::DoNotOptimize(e.kind);
            objects = e.objects_read;
        }
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(objects));
    state.counters["objects"] = static_cast<double>(objects);
}
BENCHMARK(BM_ParseRawlog)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_CopyRawlog(benchmark::State& state) {
    if (!haveInput(state)) return;
    TempOutput tmp;
    std::size_t objects = 0;
    for (auto _ : state) {
        kfd::RawlogSource source(inputPath());
        mrpt::io::CFileGZOutputStream out;
        if (!out.open(tmp.path.string(), 1)) {
            state.SkipWithError("cannot write the scratch output");
            return;
        }
        auto out_arch = mrpt::serialization::archiveFrom(out);
        objects = 0;
        kfd::SourceEntry e;
        while (source.next(e)) {
            e.forEachObject([&](const auto& obj) { out_arch << *obj; });
            objects = e.objects_read;
        }
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(objects));
    state.counters["objects"] = static_cast<double>(objects);
}
BENCHMARK(BM_CopyRawlog)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FilterRawlog(benchmark::State& state) {
    if (!haveInput(state)) return;
    TempOutput tmp;
    kfd::RawlogFilterOptions opts;
    opts.input = inputPath();
    opts.output = tmp.path.string();
    opts.pipeline = kfd::kfdDefaults();  // kfd-filter without -c (= share/kfd/default.ini)
    if (state.range(0) == 1) {
        opts.pipeline = kfd::loadConfigFile(KFD_SOURCE_DIR "/share/kfd/paper-mit-0.752.ini");
        state.SetLabel("paper-mit-0.752.ini");
    } else if (state.range(0) == 2) {
        opts.compress_level = 0;
        state.SetLabel("kfd defaults, --compress 0");
    } else {
        state.SetLabel("kfd defaults");
    }
    kfd::RawlogFilterSummary sum;
    for (auto _ : state) sum = kfd::RawlogFilter().run(opts);
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(sum.scans_in));
    state.counters["scans"] = static_cast<double>(sum.scans_in);
    state.counters["kept"] = static_cast<double>(sum.scans_kept);
    state.counters["filter_s"] = sum.filter_seconds;  // inside the pipeline, last iteration
}
BENCHMARK(BM_FilterRawlog)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
