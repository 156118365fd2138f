// kfd as a library: read a log (MRPT rawlog, ROS 1 bag or CARMEN), filter its 2D scans with
// kfd's defaults (share/kfd/default.ini) or a config file, print what was kept.
//   filter_log LOG [CONFIG]
// Every kfd error derives from kfd::Error; field() names the key, file or parameter at fault.
#include <cstdio>
#include <optional>
#include <string>

#include <kfd/io/open_source.h>
#include <kfd/mrpt/config.h>
#include <kfd/mrpt/stream_filter.h>

int main(int argc, char** argv) {
    if (argc < 2 || argc > 3) {
        std::fprintf(stderr, "usage: %s LOG [CONFIG]\n", argv[0]);
        return 2;
    }
    try {
        // kfd::StreamFilter{} runs kfd's defaults; a config file (INI or YAML) replaces them.
        kfd::StreamFilter filter(argc == 3 ? kfd::loadConfigFile(argv[2]) : kfd::kfdDefaults());
        auto source = kfd::openSource(argv[1]);  // the format is detected from the file
        kfd::SourceEntry entry;
        std::size_t scans = 0, kept = 0, points_removed = 0;
        while (source->next(entry)) {
            entry.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& scan) {
                // Cleans `scan` in place (noise marked invalid); odometry feeds the motion guards.
                const kfd::StreamResult r = filter.process(*scan, entry.odometry);
                ++scans;
                kept += r.keep;
                points_removed += r.keep ? r.report.points_in - r.report.points_out : 0;
            });
        }
        std::printf("%zu scans, %zu kept (%.1f %%), %zu points removed from kept scans\n", scans,
                    kept, scans ? 100.0 * kept / scans : 0.0, points_removed);
        return 0;
    } catch (const kfd::ConfigError& e) {  // a bad key or value: e.field() is the key
        std::fprintf(stderr, "config: %s\n", e.what());
    } catch (const kfd::SourceError& e) {  // a log that cannot be opened or read
        std::fprintf(stderr, "log: %s\n", e.what());
    } catch (const kfd::Error& e) {  // any other kfd error (a scan it cannot process, ...)
        std::fprintf(stderr, "kfd: %s\n", e.what());
    }
    return 1;
}
