// kfd-denoise-eval: precision / recall of a denoising pipeline on a labelled simulated rawlog.
#include <cstdio>
#include <string>

#include "common/cli.h"
#include "kfd/mrpt/config.h"
#include "kfd/sim/denoise_quality.h"

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-denoise-eval", "-i SIM.rawlog -l SIM.labels.csv -c CONFIG",
        "Runs every scan through the CONFIG pipeline (.ini [KFD] or .yaml; use a pipeline\n"
        "without the keyframe stage to denoise every scan) and scores the removed beams\n"
        "against kfd-simulate's labels: precision, recall, F1, recall per noise kind, and\n"
        "the fraction of true points kept.",
        "Exit 1 on bad input, 2 on bad usage.");
    std::string rawlog, labels, config;
    cli.option("-i", rawlog, "simulated rawlog (kfd-simulate)")->type_name("FILE")->required();
    cli.option("-l", labels, "its labels (OUT.labels.csv)")->type_name("FILE")->required();
    cli.option("-c", config, "pipeline configuration (.ini [KFD] or .yaml)")
        ->type_name("FILE")
        ->required();
    return cli.run(argc, argv, [&] {
        const auto q = kfd::evaluateDenoising(rawlog, labels, kfd::loadConfigFile(config));
        std::printf("scans %zu, points %zu, noise %zu (isolated %zu, clustered %zu, edge %zu)\n",
                    q.scans, q.points, q.noise, q.noise_by_kind[1], q.noise_by_kind[2],
                    q.noise_by_kind[3]);
        std::printf("precision %.4f recall %.4f f1 %.4f clean_kept %.5f\n", q.precision(),
                    q.recall(), q.f1(), q.cleanKept());
        std::printf("recall_isolated %.4f recall_clustered %.4f recall_edge %.4f\n",
                    q.recall(kfd::NoiseKind::Isolated), q.recall(kfd::NoiseKind::Clustered),
                    q.recall(kfd::NoiseKind::Edge));
        std::printf("us_per_scan %.2f\n", q.microseconds / static_cast<double>(q.scans));
    });
}
