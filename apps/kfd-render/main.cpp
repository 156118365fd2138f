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
    const kfd::StageChoice* role = kfd::defaultStageRegistry().choice("variant");
    for (const auto& st : p.stages)
        if (role && role->ofStage(st)) return st;
    return "evidence_denoise";
}

}  // namespace

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-render", "-i IN.{rawlog,bag,clf} (--index N | --time T) -o OUT.png [options]",
        "Runs the distance filter and the denoiser of CONFIG on one scan and draws its clusters\n"
        "(each in its own colour), the removed noise points (red), the ring boundaries, the "
        "sensor\n"
        "and a 1 m grid and scale bar, top-down with +x right and +y up. No display needed.\n"
        "The scans just before it go through the denoiser first (--history), as the previous\n"
        "keyframes the evidence variant compares with.");
    std::string in, out, cfg;
    long index = -1;
    double stamp = std::nan(""), extent = 0.0;
    int size = 800;
    kfd::SourceOptions source_opts;
    bool laser_only = false;
    bool list = false;
    cli.option("-i", in, "input log (rawlog, ROS 1 bag or CARMEN log)")
        ->type_name("FILE")
        ->required();
    cli.option("--index", index, "the N-th 2D scan (0-based)")->type_name("N");
    cli.option("--time", stamp, "the scan nearest to timestamp T (s)")->type_name("T");
    long history = 2;
    cli.option("--history", history, "scans before it that the denoiser sees first")
        ->type_name("K")
        ->check(kfd::app::inRange(0, 100))
        ->capture_default_str();
    cli.option("-c", cfg, "configuration (.ini [KFD] or .yaml); default: kfd's defaults")
        ->type_name("FILE");
    cli.option("-o", out, "output PNG")->type_name("FILE");
    kfd::app::addSourceOptions(cli, source_opts, list, laser_only,
                               " (the denoiser's temporal evidence then\naligns the scans "
                               "without it)");
    cli.option("--size", size, "image width and height (16 to 6324)")
        ->type_name("PX")
        ->capture_default_str();
    cli.option("--extent", extent, "half the visible height in metres (default: fit the scan)")
        ->type_name("M");
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM/SIGHUP
    return cli.run(argc, argv, [&] {
        if (list) return kfd::app::printListing(in, source_opts);
        if (out.empty()) throw kfd::app::UsageError("no output image (-o)");
        if ((index < 0) == std::isnan(stamp))
            throw kfd::app::UsageError("give exactly one of --index and --time");
        kfd::app::checkOutputPaths({{"input log", in}, {"configuration", cfg}},
                                   {{"output image", out}});
        const kfd::Pipeline::Params p = cfg.empty() ? kfd::kfdDefaults() : kfd::loadConfigFile(cfg);
        const auto source = kfd::openSource(in, source_opts);
        // The chosen scan and the `history` scans before it (with their odometry): the evidence
        // denoiser takes them as its previous keyframes.
        struct Seen {
            mrpt::obs::CObservation2DRangeScan::Ptr scan;
            std::optional<kfd::Pose2D> odometry;
            long number = 0;  // 0-based among the log's 2D scans
        };
        std::deque<Seen> recent, chosen;
        std::optional<Seen> after;  // the scan just after the chosen one (next_scan)
        bool want_after = false;
        double best = 1e300;
        long n = 0;
        kfd::SourceEntry entry;
        while (!(index >= 0 && !chosen.empty() && !want_after) && source->next(entry)) {
            kfd::throwIfCancelled();
            entry.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
                if (want_after) {
                    after = Seen{s, entry.odometry, n};
                    want_after = false;
                }
                recent.push_back({s, entry.odometry, n});
                if (recent.size() > static_cast<std::size_t>(history) + 1) recent.pop_front();
                const auto choose = [&] {
                    chosen = recent;
                    after.reset();
                    want_after = true;
                };
                if (index >= 0 && n == index) choose();
                ++n;
                if (index < 0) {
                    const double d = std::abs(kfd::stampOf(*s) - stamp);
                    if (d < best) {
                        best = d;
                        choose();
                    }
                }
            });
        }
        if (n == 0) throw std::runtime_error("no laser scan in " + in);
        if (chosen.empty())
            throw std::runtime_error("no scan " + std::to_string(index) + " in " + in +
                                     ": it holds " + std::to_string(n) +
                                     " 2D scans (--index counts from 0)");
        // Through the one door, as every tool: the distance filter and the denoiser, every scan
        // kept (no keyframe stage), so the history scans are the denoiser's previous ones. A
        // history scan the door skips is no previous keyframe; the chosen one must be usable.
        kfd::Pipeline::Params drawn = p;
        drawn.stages = {"distance", denoisingStage(p)};
        kfd::StreamFilter door(drawn, {}, true);
        door.setLaserOnly(laser_only);
        // The chosen scan's result once the door finished it; with next_scan that takes the
        // scan after it (the log's last one without it), which the door then holds, so the
        // door's last clusters are the chosen's.
        const auto* drawn_scan = chosen.back().scan.get();
        std::optional<kfd::StreamResult> finished;
        const auto keep = [&](kfd::StreamResult& f) {
            if (f.scan == drawn_scan) finished = f;
        };
        for (const Seen& seen : chosen) door.process(*seen.scan, seen.odometry, keep);
        if (!finished && after) door.process(*after->scan, after->odometry, keep);
        if (!finished) door.finish();
        const kfd::StreamResult r = *finished;
        if (r.skipped != kfd::ScanSkipReason::None) {
            char t[64];
            std::snprintf(t, sizeof(t), "%.6f", kfd::stampOf(*chosen.back().scan));
            throw std::runtime_error("scan " + std::to_string(chosen.back().number) + " of " + in +
                                     " (t = " + t + " s) cannot be drawn: it has " +
                                     kfd::describe(r.skipped) + " (" + kfd::toString(r.skipped) +
                                     ")");
        }
        // Drawn: every clustered point of the scan (the denoiser's input; noise in red).
        const auto& last = *chosen.back().scan;
        const kfd::Clusters* clusters = door.lastClusters(last.sensorLabel);
        if (!clusters) throw std::runtime_error("no clusters for the scan");
        kfd::Scan scan;
        kfd::toCore(last, scan);
        for (std::size_t i = 0; i < scan.size() && i < clusters->label.size(); ++i)
            if (clusters->label[i] >= 0) scan.valid[i] = 1;
        const auto den = r.report.findOrDefault<kfd::DenoiseResult>();
        kfd::ClusterFigureOptions o;
        o.width = o.height = size;
        o.half_extent_m = extent;
        o.ring_r_max = den.variant == kfd::DenoiseVariant::Reference ? den.r_max : 0.0;
        o.rings = std::as_const(p).get<kfd::DenoiseStage>().clustering.rings.rings;
        kfd::ClusterFigure fig(o);
        auto img = fig.render(scan, *clusters);
        kfd::TempOutputFile tmp(out);  // written under a temporary name, renamed when complete
        kfd::writePng(img, tmp.path(), out);  // every write checked (WriteError)
        kfd::throwIfCancelled();  // interrupted while drawing: nothing is moved into place
        tmp.commit();
        std::printf("kfd-render: scan at %.6f, %s, %s -> %s\n", kfd::stampOf(*chosen.back().scan),
                    kfd::plural(den.clusters, "cluster").c_str(),
                    kfd::plural(den.points_removed, "noise point").c_str(), out.c_str());
    });
}
