// kfd-simulate: simulated indoor rawlogs with ground truth and labelled noise.
// All logic lives in kfd::Simulator; this file parses arguments and reports.
#include <cstdio>
#include <string>

#include "common/cli.h"
#include "kfd/pipeline/format.h"
#include "kfd/sim/simulator.h"

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-simulate", "-o OUT.rawlog [options]",
        "Drives a robot through an indoor world, ray-casts scans (MRPT's occupancy-grid laser\n"
        "simulator), adds labelled outliers and drifting odometry. Writes OUT.rawlog\n"
        "(observations: LASER scans + ODOMETRY), OUT.gt.tum (ground truth), OUT.odom.tum and\n"
        "OUT.labels.csv (scan,timestamp,beam,kind for every outlier beam).",
        "Same options + seed = same files. Exit 1 on bad input (an output that is an input\n"
        "included), 2 on bad usage, 130/143 when interrupted (no output is left).");
    kfd::SimulationOptions o;
    cli.option("-o,--output", o.output, "output rawlog")->type_name("FILE")->required();
    cli.option("-w,--world", o.world, "built-in world: office or corridor")
        ->type_name("NAME")
        ->capture_default_str();
    cli.option("--gridmap", o.gridmap, "an MRPT .gridmap(.gz), with --route")->type_name("FILE");
    cli.option("--route", o.route, "a route (lines 'x y [stop_s [spin_deg]]'), with --gridmap")
        ->type_name("FILE");
    cli.option("-s,--sensor", o.sensor, "mit (40 Hz, 1081 beams, 270 deg) or gazebo (10 Hz, 720)")
        ->type_name("NAME")
        ->capture_default_str();
    cli.option("-v,--speed", o.speed_mps, "m/s (the paper's other group: 0.575)")
        ->type_name("V")
        ->capture_default_str();
    cli.option("-d,--duration", o.duration_s, "stop after S seconds (default: the whole route)")
        ->type_name("S");
    cli.option("--isolated", o.noise.isolated_rate, "isolated outliers, probability per beam")
        ->type_name("P")
        ->capture_default_str();
    cli.option("--clustered", o.noise.cluster_rate, "clustered outliers near the sensor, per scan")
        ->type_name("P")
        ->capture_default_str();
    cli.option("--edge", o.noise.edge_rate, "mixed pixels at depth edges, per edge")
        ->type_name("P")
        ->capture_default_str();
    cli.option("--seed", o.seed, "random seed")->type_name("N")->capture_default_str();
    cli.addQuiet("no progress");
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM/SIGHUP
    return cli.run(argc, argv, [&] {
        if (o.gridmap.empty() != o.route.empty())
            throw kfd::app::UsageError("--gridmap and --route go together");
        if (auto* progress = cli.progress())
            o.on_progress = [progress](double f, std::size_t scans) { progress->update(f, scans); };
        const auto s = kfd::Simulator().run(o);
        std::printf("kfd-simulate: %s, %.1f s, %.1f m driven\n",
                    kfd::plural(s.scans, "scan").c_str(), s.duration_s, s.distance_m);
        std::printf("  outliers   isolated %zu, clustered %zu, edge %zu\n", s.noise_isolated,
                    s.noise_clustered, s.noise_edge);
        std::printf("  wrote      %s, %s, %s, %s\n", s.rawlog.c_str(), s.ground_truth.c_str(),
                    s.odometry.c_str(), s.labels.c_str());
    });
}
