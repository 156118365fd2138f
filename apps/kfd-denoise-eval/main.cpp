// kfd-denoise-eval: precision / recall of a denoising pipeline on a labelled simulated rawlog.
#include <cstdio>
#include <string>

#include "kfd/mrpt/config.h"
#include "kfd/sim/denoise_quality.h"

int main(int argc, char** argv) {
    std::string rawlog, labels, config;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-h" || a == "--help") {
            std::puts(
                "Usage: kfd-denoise-eval -i SIM.rawlog -l SIM.labels.csv -c CONFIG\n"
                "Runs every scan through the CONFIG pipeline (.ini [KFD] or .yaml; use a pipeline\n"
                "without the keyframe stage to denoise every scan) and scores the removed beams\n"
                "against kfd-simulate's labels: precision, recall, F1, recall per noise kind, and\n"
                "the fraction of true points kept. Exit 1 on bad input, 2 on bad usage.");
            return 0;
        }
        if (i + 1 >= argc) {
            std::fprintf(stderr, "kfd-denoise-eval: %s needs a value (see --help)\n", a.c_str());
            return 2;
        }
        const std::string v = argv[++i];
        if (a == "-i")
            rawlog = v;
        else if (a == "-l")
            labels = v;
        else if (a == "-c")
            config = v;
        else {
            std::fprintf(stderr, "kfd-denoise-eval: unknown option '%s' (see --help)\n", a.c_str());
            return 2;
        }
    }
    if (rawlog.empty() || labels.empty() || config.empty()) {
        std::fprintf(stderr, "kfd-denoise-eval: -i, -l and -c are required (see --help)\n");
        return 2;
    }
    try {
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
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd-denoise-eval: %s\n", e.what());
        return 1;
    }
    return 0;
}
