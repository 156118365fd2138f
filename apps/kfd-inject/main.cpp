// kfd-inject: labelled noise injected into a REAL rawlog, several models per kind, for scoring
// denoisers on real scans (kfd-denoise-eval). All logic lives in kfd::writeNoisyLog.
#include <cstdio>
#include <string>

#include "common/cli.h"
#include "kfd/pipeline/format.h"
#include "kfd/sim/noisy_log.h"

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-inject", "-i REAL.rawlog -o NOISY.rawlog [options]",
        "Copies a real rawlog, adding labelled outliers to every 2D scan: isolated spikes,\n"
        "clustered bursts and mixed pixels at depth edges, each drawn from three models\n"
        "(kfd/sim/real_noise.h), so that no denoiser can be fitted to one. Every other return\n"
        "is the sensor's own. Writes NOISY.rawlog and NOISY.labels.csv\n"
        "(scan,timestamp,beam,kind,model); score a pipeline with kfd-denoise-eval.",
        "Same input, options and seed = same files. Exit 1 on bad input (an output that is the\n"
        "input included), 2 on bad usage, 130/143 when interrupted (no output is left).");
    kfd::NoisyLogOptions o;
    cli.option("-i,--input", o.input, "real rawlog")->type_name("FILE")->required();
    cli.option("-o,--output", o.output, "noisy rawlog")->type_name("FILE")->required();
    cli.option("--isolated", o.noise.isolated_rate, "isolated spikes, probability per beam")
        ->type_name("P")
        ->capture_default_str();
    cli.option("--clustered", o.noise.cluster_rate, "clustered bursts per scan (Poisson mean)")
        ->type_name("N")
        ->capture_default_str();
    cli.option("--edge", o.noise.edge_rate, "mixed pixels, probability per depth edge")
        ->type_name("P")
        ->capture_default_str();
    cli.option("--model", o.noise.only,
               "only this model (spike_uniform, spike_near_sensor, spike_near_surface,\n"
               "cluster_near_sensor, cluster_mid_range, cluster_before_wall, edge_uniform,\n"
               "edge_near_front, edge_near_back); default: all of them",
               kfd::parseNoiseModel)
        ->type_name("NAME");
    cli.option("--seed", o.seed, "random seed")->type_name("N")->capture_default_str();
    cli.addQuiet("no progress");
    cli.cancelOnSignal();  // outputs: stop cleanly on SIGINT/SIGTERM/SIGHUP
    return cli.run(argc, argv, [&] {
        if (auto* progress = cli.progress())
            o.on_progress = [progress](double f, std::size_t scans) { progress->update(f, scans); };
        const auto s = kfd::writeNoisyLog(o);
        std::printf("kfd-inject: %s, %s\n", kfd::plural(s.scans, "scan").c_str(),
                    kfd::plural(s.beams, "valid beam").c_str());
        std::printf("  outliers   isolated %zu, clustered %zu, edge %zu\n", s.by_kind[1],
                    s.by_kind[2], s.by_kind[3]);
        std::printf("  wrote      %s, %s\n", s.rawlog.c_str(), s.labels.c_str());
    });
}
