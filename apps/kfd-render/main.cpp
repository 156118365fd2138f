// kfd-render: renders the clusters of one scan of a rawlog to PNG (off-screen, OSMesa).
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "kfd/core/denoiser.h"
#include "kfd/core/distance_filter.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/render/cluster_figure.h"

namespace {
const char* kUsage =
    "Usage: kfd-render -i IN.rawlog (--index N | --time T) -o OUT.png [options]\n"
    "\n"
    "Runs the distance filter and the denoiser of CONFIG on one scan and draws its clusters\n"
    "(each in its own colour), the removed noise points (red), the ring boundaries, the sensor\n"
    "and a 1 m grid and scale bar, top-down with +x right and +y up. No display needed.\n"
    "\n"
    "  -i FILE        rawlog\n"
    "  --index N      the N-th 2D scan (0-based)\n"
    "  --time T       the scan nearest to timestamp T (s)\n"
    "  -c FILE        configuration (.ini [KFD] or .yaml); default: built-in defaults\n"
    "  -o FILE        output PNG\n"
    "  --size PX      image width and height (default 800)\n"
    "  --extent M     half the visible height in metres (default: fit the scan)\n";

int usage(const std::string& m) {
    std::fprintf(stderr, "kfd-render: %s\nTry 'kfd-render --help'.\n", m.c_str());
    return 2;
}
}  // namespace

int main(int argc, char** argv) {
    std::string in, out, cfg;
    long index = -1;
    double stamp = std::nan(""), extent = 0.0;
    int size = 800;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        }
        if (i + 1 >= argc) return usage(a + " needs a value");
        const std::string v = argv[++i];
        try {
            if (a == "-i")
                in = v;
            else if (a == "-o")
                out = v;
            else if (a == "-c")
                cfg = v;
            else if (a == "--index")
                index = std::stol(v);
            else if (a == "--time")
                stamp = std::stod(v);
            else if (a == "--size")
                size = std::stoi(v);
            else if (a == "--extent")
                extent = std::stod(v);
            else
                return usage("unknown option '" + a + "'");
        } catch (const std::exception& e) {
            return usage(a + ": " + e.what());
        }
    }
    if (in.empty() || out.empty()) return usage("-i and -o are required");
    if ((index < 0) == std::isnan(stamp)) return usage("give exactly one of --index and --time");
    try {
        const kfd::Pipeline::Params p =
            cfg.empty() ? kfd::Pipeline::Params{} : kfd::loadConfigFile(cfg);
        mrpt::io::CFileGZInputStream f;
        if (!f.open(in)) throw std::runtime_error("cannot open " + in);
        auto arch = mrpt::serialization::archiveFrom(f);
        mrpt::obs::CObservation2DRangeScan::Ptr chosen;
        double best = 1e300;
        long n = 0;
        for (;;) {
            mrpt::serialization::CSerializable::Ptr obj;
            try {
                obj = arch.ReadObject();
            } catch (const mrpt::serialization::CExceptionEOF&) {
                break;
            }
            // Scans stand alone (observations layout) or inside sensory frames.
            std::vector<mrpt::obs::CObservation2DRangeScan::Ptr> scans;
            if (auto s = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(obj))
                scans.push_back(s);
            if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(obj))
                for (const auto& o : *sf)
                    if (auto s = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(o))
                        scans.push_back(s);
            for (const auto& s : scans) {
                if (index >= 0 && n++ == index) chosen = s;
                if (index < 0) {
                    const double d = std::abs(mrpt::Clock::toDouble(s->timestamp) - stamp);
                    if (d < best) {
                        best = d;
                        chosen = s;
                    }
                }
            }
            if (index >= 0 && chosen) break;
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
        if (!img.saveToFile(out)) throw std::runtime_error("cannot write " + out);
        std::printf("kfd-render: scan at %.6f, %zu clusters, %zu noise points -> %s\n",
                    mrpt::Clock::toDouble(chosen->timestamp), r.clusters, r.points_removed,
                    out.c_str());
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd-render: %s\n", e.what());
        return 1;
    }
    return 0;
}
