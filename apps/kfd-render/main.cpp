// kfd-render: renders the clusters of one scan of a log (rawlog, bag, CARMEN) to PNG (off-screen,
// OSMesa).
#include <mrpt/obs/CObservation2DRangeScan.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <optional>
#include <string>
#include <utility>

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

// The denoising stage the configuration's pipeline runs (selected by `variant`), kfd's
// evidence_denoise when it lists none.
std::string denoisingStage(const kfd::Pipeline::Params& p) {
    const auto* listed = kfd::defaultStageRegistry().choice("variant")->listedIn(p.stages);
    return listed ? listed->stage : "evidence_denoise";
}

struct Options {
    std::string in, out, cfg;
    long index = -1;
    double stamp = std::nan("");
    double extent = 0.0;
    int size = 800;
    long history = 2;
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
    cli.option("--history", o.history, "scans before it that the denoiser sees first")
        ->type_name("K")
        ->check(kfd::app::inRange(0, 100))
        ->capture_default_str();
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

// A 2D scan of the log with its odometry and its 0-based number among the log's 2D scans.
struct Seen {
    mrpt::obs::CObservation2DRangeScan::Ptr scan;
    std::optional<kfd::Pose2D> odometry;
    long number = 0;
};

// The chosen scan and the `history` scans before it (the evidence denoiser's previous
// keyframes), and the scan just after it (next_scan).
struct Chosen {
    std::deque<Seen> scans;  // the chosen one last
    std::optional<Seen> after;
};

Chosen chooseScans(const Options& o) {
    const auto source = kfd::openSource(o.in, o.source);
    std::deque<Seen> recent;
    Chosen c;
    bool want_after = false;
    double best = 1e300;
    long n = 0;
    kfd::SourceEntry entry;
    while (!(o.index >= 0 && !c.scans.empty() && !want_after) && source->next(entry)) {
        kfd::throwIfCancelled();
        entry.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
            if (want_after) {
                c.after = Seen{s, entry.odometry, n};
                want_after = false;
            }
            recent.push_back({s, entry.odometry, n});
            if (recent.size() > static_cast<std::size_t>(o.history) + 1) recent.pop_front();
            const double d = std::abs(kfd::stampOf(*s) - o.stamp);
            if ((o.index >= 0 && n == o.index) || (o.index < 0 && d < best)) {
                best = d;
                c.scans = recent;
                c.after.reset();
                want_after = true;
            }
            ++n;
        });
    }
    if (n == 0) throw std::runtime_error("no laser scan in " + o.in);
    if (c.scans.empty())
        throw std::runtime_error("no scan " + std::to_string(o.index) + " in " + o.in +
                                 ": it holds " + std::to_string(n) +
                                 " 2D scans (--index counts from 0)");
    return c;
}

// Through the one door, as every tool: the distance filter and the denoiser, every scan kept
// (no keyframe stage), so the history scans are the denoiser's previous ones. The chosen
// scan's result once the door finished it; with next_scan that takes the scan after it (the
// log's last one without it), which the door then holds, so the door's last clusters are the
// chosen's. A history scan the door skips is no previous keyframe; the chosen one must be
// usable.
kfd::StreamResult denoise(const Options& o, const Chosen& c, kfd::StreamFilter& door) {
    const auto* drawn_scan = c.scans.back().scan.get();
    std::optional<kfd::StreamResult> finished;
    const auto keep = [&](kfd::StreamResult& f) {
        if (f.scan == drawn_scan) finished = f;
    };
    for (const Seen& seen : c.scans) door.process(*seen.scan, seen.odometry, keep);
    if (!finished && c.after) door.process(*c.after->scan, c.after->odometry, keep);
    if (!finished) door.finish();
    if (finished->skipped != kfd::ScanSkipReason::None) {
        char t[64];
        std::snprintf(t, sizeof(t), "%.6f", kfd::stampOf(*c.scans.back().scan));
        throw std::runtime_error("scan " + std::to_string(c.scans.back().number) + " of " + o.in +
                                 " (t = " + t + " s) cannot be drawn: it has " +
                                 kfd::describe(finished->skipped) + " (" +
                                 kfd::toString(finished->skipped) + ")");
    }
    return *finished;
}

// Draws every clustered point of the scan (the denoiser's input; noise in red) and writes the
// PNG under a temporary name, renamed when complete.
void draw(const Options& o, const kfd::Pipeline::Params& p, const Chosen& c,
          const kfd::StreamResult& r, const kfd::StreamFilter& door) {
    const auto& last = *c.scans.back().scan;
    const kfd::Clusters* clusters = door.lastClusters(last.sensorLabel);
    if (!clusters) throw std::runtime_error("no clusters for the scan");
    kfd::Scan scan;
    kfd::toCore(last, scan);
    for (std::size_t i = 0; i < scan.size() && i < clusters->label.size(); ++i)
        if (clusters->label[i] >= 0) scan.valid[i] = 1;
    const auto den = r.report.findOrDefault<kfd::DenoiseResult>();
    kfd::ClusterFigureOptions fo;
    fo.width = fo.height = o.size;
    fo.half_extent_m = o.extent;
    fo.ring_r_max = den.variant == kfd::DenoiseVariant::Reference ? den.r_max : 0.0;
    fo.rings = p.get<kfd::DenoiseStage>().clustering.rings.rings;
    kfd::ClusterFigure fig(fo);
    auto img = fig.render(scan, *clusters);
    kfd::TempOutputFile tmp(o.out);
    kfd::writePng(img, tmp.path(), o.out);  // every write checked (WriteError)
    kfd::throwIfCancelled();                // interrupted while drawing: nothing is moved
    tmp.commit();
    std::printf("kfd-render: scan at %.6f, %s, %s -> %s\n", kfd::stampOf(last),
                kfd::plural(den.clusters, "cluster").c_str(),
                kfd::plural(den.points_removed, "noise point").c_str(), o.out.c_str());
}

}  // namespace

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-render", "-i IN.{rawlog,bag,db3,mcap,clf} (--index N | --time T) -o OUT.png [options]",
        "Runs the distance filter and the denoiser of CONFIG on one scan and draws its clusters\n"
        "(each in its own colour), the removed noise points (red), the ring boundaries, the "
        "sensor\n"
        "and a 1 m grid and scale bar, top-down with +x right and +y up. No display needed.\n"
        "The scans just before it go through the denoiser first (--history), as the previous\n"
        "keyframes the evidence variant compares with.");
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
        const Chosen c = chooseScans(o);
        kfd::Pipeline::Params drawn = p;
        drawn.stages = {"distance", denoisingStage(p)};
        kfd::StreamFilter door(drawn, {}, true);
        door.setLaserOnly(o.laser_only);
        const kfd::StreamResult r = denoise(o, c, door);
        draw(o, p, c, r, door);
    });
}
