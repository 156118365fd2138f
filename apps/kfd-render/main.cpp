// kfd-render: renders the clusters of one scan of a log (rawlog, bag, CARMEN) to PNG (off-screen,
// OSMesa).
#include <mrpt/obs/CObservation2DRangeScan.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/cli.h"
#include "common/config_cli.h"
#include "common/source_cli.h"
#include "kfd/io/open_source.h"
#include "kfd/io/png_output.h"
#include "kfd/io/source.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/default_stages.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/os/cancel.h"
#include "kfd/pipeline/format.h"
#include "kfd/render/cluster_figure.h"
#include "kfd/stages/denoise_result.h"
#include "kfd/stages/denoise_stage.h"

namespace {

struct Options {
    std::string in, out, cfg;
    long index = -1;
    double stamp = std::nan("");
    double extent = 0.0;
    int size = 800;
    kfd::SourceOptions source;
    bool laser_only = false;
    bool list = false;
};

void addOptions(kfd::app::Cli& cli, Options& o) {
    cli.option("-i", o.in, "input log (rawlog, ROS 1 or ROS 2 bag, or CARMEN log)")
        ->type_name("FILE")
        ->required();
    cli.option("--index", o.index, "the N-th 2D scan (0-based)")->type_name("N");
    cli.option("--time", o.stamp, "the scan nearest to timestamp T (s)")->type_name("T");
    cli.option("-c", o.cfg, "configuration (.ini [KFD] or .yaml); default: kfd's defaults")
        ->type_name("FILE");
    cli.option("-o", o.out, "output PNG")->type_name("FILE");
    kfd::app::addSourceOptions(cli, o.source, o.list, o.laser_only,
                               " (the denoiser's temporal evidence then\naligns the scans "
                               "without it)");
    cli.option("--size", o.size, "image width and height (16 to 6324)")
        ->type_name("PX")
        ->capture_default_str();
    cli.option("--extent", o.extent, "half the visible height in metres (default: fit the scan)")
        ->type_name("M");
}

// The number (0-based, among the log's 2D scans) of the scan nearest to --time: a first pass
// over the log (--index needs none).
long nearestNumber(const Options& o) {
    const auto source = kfd::openSource(o.in, o.source);
    kfd::SourceEntry entry;
    long n = 0, best_n = -1;
    double best = 1e300;
    while (source->next(entry)) {
        kfd::throwIfCancelled();
        entry.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
            const double d = std::abs(kfd::stampOf(*s) - o.stamp);
            if (d < best) {
                best = d;
                best_n = n;
            }
            ++n;
        });
    }
    if (n == 0) throw std::runtime_error("no laser scan in " + o.in);
    return best_n;
}

// The chosen scan as kfd-filter decided it.
struct Decided {
    mrpt::obs::CObservation2DRangeScan::Ptr scan;  // as the door left it
    kfd::Scan before;                              // as it came in
    kfd::StreamResult result;
    long number = 0;
};

// The log from its first scan through the door with the configuration's whole pipeline, as
// kfd-filter runs it, up to the chosen scan; with next_scan also the scan after it, which
// finishes the chosen keyframe (the door then holds the later one, so its last clusters are
// the chosen's). The chosen scan must be usable.
Decided decide(const Options& o, long number, kfd::StreamFilter& door) {
    const auto source = kfd::openSource(o.in, o.source);
    kfd::SourceEntry entry;
    Decided d;
    d.number = number;
    std::optional<kfd::StreamResult> finished;
    // The scans the door holds (next_scan) stay alive until it hands them back finished: the
    // source reuses its entry.
    std::map<const void*, mrpt::obs::CObservation2DRangeScan::Ptr> held;
    std::vector<const void*> done;
    const auto keep = [&](kfd::StreamResult& f) {
        if (d.scan && f.scan == d.scan.get()) finished = f;
        done.push_back(f.scan);
    };
    long n = 0;
    while (!finished && source->next(entry)) {
        kfd::throwIfCancelled();
        entry.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
            if (finished) return;
            if (n == number) {
                d.scan = s;
                kfd::toCore(*s, d.before);
            }
            held[s.get()] = s;
            door.process(*s, entry.odometry, keep);
            for (const void* p : done) held.erase(p);
            done.clear();
            ++n;
        });
    }
    if (n == 0) throw std::runtime_error("no laser scan in " + o.in);
    if (!d.scan)
        throw std::runtime_error("no scan " + std::to_string(number) + " in " + o.in +
                                 ": it holds " + std::to_string(n) +
                                 " 2D scans (--index counts from 0)");
    if (!finished) door.finish();
    d.result = *finished;
    if (d.result.skipped != kfd::ScanSkipReason::None) {
        char t[64];
        std::snprintf(t, sizeof(t), "%.6f", kfd::stampOf(*d.scan));
        throw std::runtime_error("scan " + std::to_string(number) + " of " + o.in + " (t = " + t +
                                 " s) cannot be drawn: it has " + kfd::describe(d.result.skipped) +
                                 " (" + kfd::toString(d.result.skipped) + ")");
    }
    return d;
}

// What is drawn of a dropped scan: its valid returns as one cluster (the denoiser never ran).
kfd::Clusters oneCluster(const kfd::Scan& scan) {
    kfd::Clusters c;
    c.label.assign(scan.size(), -1);
    for (std::size_t i = 0; i < scan.size(); ++i)
        if (scan.valid[i]) c.label[i] = 0;
    c.size = {static_cast<std::uint32_t>(scan.countValid())};
    c.mean_range = {0.0f};
    c.noise = {0};
    return c;
}

// "fr079.rawlog, scan 1200 (t = 1234.5 s): KEPT (view_change), 342 returns, 3 removed as noise
// (0.88 %)": what kfd-filter's per-scan CSV says of the scan.
std::string title(const Options& o, const Decided& d) {
    const kfd::ScanRecord& r = d.result.record;
    const std::string name = std::filesystem::path(o.in).filename().string();
    return kfd::format(
        "%s, scan %ld (t = %.3f s): %s (%s), %zu returns, %zu removed as noise "
        "(%.2f %%)",
        name.c_str(), d.number, kfd::stampOf(*d.scan), r.kept ? "KEPT" : "DROPPED", r.reason,
        r.points_in, r.removed_noise,
        r.points_in ? 100.0 * double(r.removed_noise) / double(r.points_in) : 0.0);
}

// Draws the scan as it entered the denoiser (every clustered point; noise in red), or a dropped
// scan's returns, and writes the PNG under a temporary name, renamed when complete.
void draw(const Options& o, const kfd::Pipeline::Params& p, const Decided& d,
          const kfd::StreamFilter& door) {
    kfd::Scan scan;
    kfd::toCore(*d.scan, scan);
    kfd::Clusters dropped;
    const kfd::Clusters* clusters =
        d.result.record.kept ? door.lastClusters(d.scan->sensorLabel) : nullptr;
    if (!clusters) {  // dropped, or a pipeline without a denoiser: the returns as they came
        scan = d.before;
        dropped = oneCluster(scan);
        clusters = &dropped;
    }
    for (std::size_t i = 0; i < scan.size() && i < clusters->label.size(); ++i)
        if (clusters->label[i] >= 0) scan.valid[i] = 1;
    const auto den = d.result.report.findOrDefault<kfd::DenoiseResult>();
    kfd::ClusterFigureOptions fo;
    fo.width = fo.height = o.size;
    fo.half_extent_m = o.extent;
    fo.ring_r_max = den.variant == kfd::DenoiseVariant::Reference ? den.r_max : 0.0;
    fo.rings = p.get<kfd::DenoiseStage>().clustering.rings.rings;
    fo.title = title(o, d);
    kfd::ClusterFigure fig(fo);
    auto img = fig.render(scan, *clusters);
    kfd::TempOutputFile tmp(o.out);
    kfd::writePng(img, tmp.path(), o.out);  // every write checked (WriteError)
    kfd::throwIfCancelled();                // interrupted while drawing: nothing is moved
    tmp.commit();
    std::printf("kfd-render: %s -> %s\n", fo.title.c_str(), o.out.c_str());
}

}  // namespace

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-render", "-i IN.{rawlog,bag,db3,mcap,clf} (--index N | --time T) -o OUT.png [options]",
        "Runs the log up to one scan through CONFIG's pipeline exactly as kfd-filter does and\n"
        "draws that scan: its clusters (each in its own colour), the removed noise points (red),\n"
        "the ring boundaries, the sensor and a 1 m grid and scale bar, top-down with +x right\n"
        "and +y up, titled with kfd-filter's row for it (kept or dropped, why, returns,\n"
        "removed). A dropped scan is drawn as it came in. No display needed.");
    Options o;
    addOptions(cli, o);
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM/SIGHUP
    return cli.run(argc, argv, [&] {
        if (o.list) return kfd::app::printListing(o.in, o.source);
        if (o.out.empty()) throw kfd::app::UsageError("no output image (-o)");
        if ((o.index < 0) == std::isnan(o.stamp))
            throw kfd::app::UsageError("give exactly one of --index and --time");
        kfd::app::checkOutputPaths({{"input log", o.in}, {"configuration", o.cfg}},
                                   {{"output image", o.out}});
        const kfd::Pipeline::Params p = kfd::app::loadConfig(o.cfg, "kfd-render");
        const long number = o.index >= 0 ? o.index : nearestNumber(o);
        kfd::StreamFilter door(p, {}, true);
        door.setLaserOnly(o.laser_only);
        const Decided d = decide(o, number, door);
        draw(o, p, d, door);
    });
}
