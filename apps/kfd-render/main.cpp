// kfd-render: renders the clusters of one scan of a rawlog to PNG (off-screen, OSMesa).
#include <mrpt/obs/CObservation2DRangeScan.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "common/cli.h"
#include "kfd/core/cancel.h"
#include "kfd/core/denoiser.h"
#include "kfd/core/distance_filter.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/mrpt/source.h"
#include "kfd/render/cluster_figure.h"

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-render", "-i IN.rawlog (--index N | --time T) -o OUT.png [options]",
        "Runs the distance filter and the denoiser of CONFIG on one scan and draws its clusters\n"
        "(each in its own colour), the removed noise points (red), the ring boundaries, the "
        "sensor\n"
        "and a 1 m grid and scale bar, top-down with +x right and +y up. No display needed.");
    std::string in, out, cfg;
    long index = -1;
    double stamp = std::nan(""), extent = 0.0;
    int size = 800;
    cli.option("-i", in, "rawlog")->type_name("FILE")->required();
    cli.option("--index", index, "the N-th 2D scan (0-based)")->type_name("N");
    cli.option("--time", stamp, "the scan nearest to timestamp T (s)")->type_name("T");
    cli.option("-c", cfg, "configuration (.ini [KFD] or .yaml); default: built-in defaults")
        ->type_name("FILE");
    cli.option("-o", out, "output PNG")->type_name("FILE")->required();
    cli.option("--size", size, "image width and height")->type_name("PX")->capture_default_str();
    cli.option("--extent", extent, "half the visible height in metres (default: fit the scan)")
        ->type_name("M");
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM
    return cli.run(argc, argv, [&] {
        if ((index < 0) == std::isnan(stamp))
            throw kfd::app::UsageError("give exactly one of --index and --time");
        kfd::app::checkOutputPaths({{"input rawlog", in}, {"configuration", cfg}},
                                   {{"output image", out}});
        const kfd::Pipeline::Params p =
            cfg.empty() ? kfd::Pipeline::Params{} : kfd::loadConfigFile(cfg);
        const auto source = kfd::openSource(in);
        mrpt::obs::CObservation2DRangeScan::Ptr chosen;
        double best = 1e300;
        long n = 0;
        kfd::SourceEntry entry;
        while (!(index >= 0 && chosen) && source->next(entry)) {
            kfd::throwIfCancelled();
            entry.forEachScan([&](const mrpt::obs::CObservation2DRangeScan::Ptr& s) {
                if (index >= 0 && n++ == index) chosen = s;
                if (index < 0) {
                    const double d = std::abs(kfd::stampOf(*s) - stamp);
                    if (d < best) {
                        best = d;
                        chosen = s;
                    }
                }
            });
        }
        if (!chosen) throw std::runtime_error("no such scan in " + in);
        kfd::Scan scan;
        kfd::toCore(*chosen, scan);
        kfd::DistanceFilter(p.get<kfd::DistanceStage>()).filter(scan);
        kfd::Scan work = scan;
        kfd::Denoiser den(p.get<kfd::DenoiseStage>());
        const auto r = den.filter(work);
        kfd::ClusterFigureOptions o;
        o.width = o.height = size;
        o.half_extent_m = extent;
        o.ring_r_max =
            p.get<kfd::DenoiseStage>().variant == kfd::DenoiseVariant::Reference ? r.r_max : 0.0;
        o.rings = p.get<kfd::DenoiseStage>().reference.rings.rings;
        kfd::ClusterFigure fig(o);
        auto img = fig.render(scan, den.clusters());
        kfd::TempOutputFile tmp(out);  // written under a temporary name, renamed when complete
        if (!img.saveToFile(tmp.path().string())) throw std::runtime_error("cannot write " + out);
        kfd::throwIfCancelled();  // interrupted while drawing: nothing is moved into place
        tmp.commit();
        std::printf("kfd-render: scan at %.6f, %zu clusters, %zu noise points -> %s\n",
                    kfd::stampOf(*chosen), r.clusters, r.points_removed, out.c_str());
    });
}
