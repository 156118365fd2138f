// kfd-denoise-eval: precision / recall of a denoising pipeline on a labelled rawlog
// (kfd-simulate's or kfd-inject's).
#include <cstdio>
#include <string>

#include "common/cli.h"
#include "common/config_cli.h"
#include "kfd/mrpt/config.h"
#include "kfd/sim/denoise_quality.h"

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-denoise-eval", "-i SIM.rawlog -l SIM.labels.csv -c CONFIG",
        "Runs every scan through the CONFIG pipeline (.ini [KFD] or .yaml) and scores the\n"
        "removed beams of the scans it keeps (all, without a keyframe stage)\n"
        "against the labels of kfd-simulate or kfd-inject: precision, recall, F1, recall per\n"
        "noise kind (and per model, for kfd-inject's labels), the fraction of true points\n"
        "kept and the share removed by range (0-2, 2-5, 5-10, 10+ m).",
        "Exit 1 on bad input, 2 on bad usage.");
    std::string rawlog, labels, config;
    bool laser_only = false;
    cli.option("-i", rawlog, "labelled rawlog (kfd-simulate or kfd-inject)")
        ->type_name("FILE")
        ->required();
    cli.option("-l", labels,
               "its labels (OUT.labels.csv); an empty label file (header only)\nscores a clean "
               "log: what a method removes of real returns")
        ->type_name("FILE")
        ->required();
    cli.option("-c", config, "pipeline configuration (.ini [KFD] or .yaml)")
        ->type_name("FILE")
        ->required();
    cli.flag("--laser-only", laser_only,
             "withhold the log's odometry from the pipeline (as from a LaserScan-only source)");
    return cli.run(argc, argv, [&] {
        const auto q = kfd::evaluateDenoising(
            rawlog, labels, kfd::app::loadConfig(config, "kfd-denoise-eval"), laser_only);
        std::printf(
            "scans %zu (scored %zu kept of %zu), points %zu, noise %zu (isolated %zu, "
            "clustered %zu, edge %zu)\n",
            q.scans, q.scored, q.scans, q.points, q.noise, q.noise_by_kind[1], q.noise_by_kind[2],
            q.noise_by_kind[3]);
        std::printf("precision %.4f recall %.4f f1 %.4f clean_kept %.5f\n", q.precision(),
                    q.recall(), q.f1(), q.cleanKept());
        std::printf("recall_isolated %.4f recall_clustered %.4f recall_edge %.4f\n",
                    q.recall(kfd::NoiseKind::Isolated), q.recall(kfd::NoiseKind::Clustered),
                    q.recall(kfd::NoiseKind::Edge));
        std::printf("us_per_scan %.2f\n", q.microseconds / static_cast<double>(q.scans));
        std::printf("clean_removed_by_range");
        for (std::size_t b = 0; b < q.clean_by_band.size(); ++b)
            std::printf(" %g-%s:%.5f", q.kBandStartM[b],
                        b + 1 < q.kBandStartM.size()
                            ? std::to_string(static_cast<int>(q.kBandStartM[b + 1])).c_str()
                            : "inf",
                        q.cleanRemoved(b));
        std::printf("\n");
        for (std::size_t m = 1; m < kfd::kNoiseModels; ++m) {
            const auto model = static_cast<kfd::NoiseModel>(m);
            if (q.noise_by_model[m])
                std::printf("recall_%s %.4f (%zu)\n", kfd::toString(model), q.recall(model),
                            q.noise_by_model[m]);
        }
    });
}
