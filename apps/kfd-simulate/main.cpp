// kfd-simulate: simulated indoor rawlogs with ground truth and labelled noise.
// All logic lives in kfd::Simulator; this file parses arguments and reports.
#include <cstdio>
#include <string>

#include "common/progress.h"
#include "kfd/sim/simulator.h"

namespace {

const char* kUsage =
    "Usage: kfd-simulate -o OUT.rawlog [options]\n"
    "\n"
    "Drives a robot through an indoor world, ray-casts scans (MRPT's occupancy-grid laser\n"
    "simulator), adds labelled outliers and drifting odometry. Writes OUT.rawlog\n"
    "(observations: LASER scans + ODOMETRY), OUT.gt.tum (ground truth), OUT.odom.tum and\n"
    "OUT.labels.csv (scan,timestamp,beam,kind for every outlier beam).\n"
    "\n"
    "  -w, --world NAME        built-in world: office (default) or corridor\n"
    "      --gridmap FILE --route FILE\n"
    "                          an MRPT .gridmap(.gz) and a route (lines 'x y [stop_s "
    "[spin_deg]]')\n"
    "  -s, --sensor NAME       mit (40 Hz, 1081 beams, 270 deg; default) or gazebo (10 Hz, 720)\n"
    "  -v, --speed V           m/s (default 0.752; the paper's other group: 0.575)\n"
    "  -d, --duration S        stop after S seconds (default: the whole route)\n"
    "      --isolated P        isolated outliers, probability per beam (default 0.005)\n"
    "      --clustered P       clustered outliers near the sensor, per scan (default 0.05)\n"
    "      --edge P            mixed pixels at depth edges, per edge (default 0.3)\n"
    "      --seed N            random seed (default 1); same options + seed = same files\n"
    "  -q, --quiet             no progress\n"
    "  -h, --help              this text\n";

int usageError(const std::string& m) {
    std::fprintf(stderr, "kfd-simulate: %s\nTry 'kfd-simulate --help'.\n", m.c_str());
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    kfd::SimulationOptions o;
    bool quiet = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        }
        if (a == "-q" || a == "--quiet") {
            quiet = true;
            continue;
        }
        if (i + 1 >= argc)
            return usageError(a.rfind("-", 0) == 0 ? a + " needs a value"
                                                   : "unexpected '" + a + "'");
        const std::string v = argv[++i];
        try {
            if (a == "-o" || a == "--output")
                o.output = v;
            else if (a == "-w" || a == "--world")
                o.world = v;
            else if (a == "--gridmap")
                o.gridmap = v;
            else if (a == "--route")
                o.route = v;
            else if (a == "-s" || a == "--sensor")
                o.sensor = v;
            else if (a == "-v" || a == "--speed")
                o.speed_mps = std::stod(v);
            else if (a == "-d" || a == "--duration")
                o.duration_s = std::stod(v);
            else if (a == "--isolated")
                o.noise.isolated_rate = std::stod(v);
            else if (a == "--clustered")
                o.noise.cluster_rate = std::stod(v);
            else if (a == "--edge")
                o.noise.edge_rate = std::stod(v);
            else if (a == "--seed")
                o.seed = static_cast<std::uint32_t>(std::stoul(v));
            else
                return usageError("unknown option '" + a + "'");
        } catch (const std::exception& e) {
            return usageError(a + ": " + e.what());
        }
    }
    if (o.output.empty()) return usageError("no output rawlog (-o)");
    if (o.gridmap.empty() != o.route.empty())
        return usageError("--gridmap and --route go together");
    kfd::app::ProgressPrinter progress("kfd-simulate");
    if (!quiet) o.on_progress = [&](double f) { progress.update(f, 0, 0); };
    try {
        const auto s = kfd::Simulator().run(o);
        std::printf("kfd-simulate: %zu scans, %.1f s, %.1f m driven\n", s.scans, s.duration_s,
                    s.distance_m);
        std::printf("  outliers   isolated %zu, clustered %zu, edge %zu\n", s.noise_isolated,
                    s.noise_clustered, s.noise_edge);
        std::printf("  wrote      %s, %s, %s, %s\n", s.rawlog.c_str(), s.ground_truth.c_str(),
                    s.odometry.c_str(), s.labels.c_str());
    } catch (const std::exception& e) {
        if (!quiet) progress.abort();
        std::fprintf(stderr, "kfd-simulate: %s\n", e.what());
        return 1;
    }
    return 0;
}
