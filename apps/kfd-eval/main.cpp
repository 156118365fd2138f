// kfd-eval: trajectory error against ground truth (relations metric, ATE, RPE).
#include <cstdio>
#include <string>

#include "kfd/eval/ate.h"
#include "kfd/eval/relations.h"

namespace {

const char* kUsage =
    "Usage: kfd-eval EST.tum [--relations GT.relations] [--gt GT.tum] [options]\n"
    "\n"
    "  -r, --relations FILE  Kuemmerle et al. 2009 relations metric (mean +- std of the\n"
    "                        translation error in m and rotation error in deg, absolute and\n"
    "                        squared)\n"
    "  -g, --gt FILE         ground-truth TUM trajectory: ATE RMSE after SE(2) alignment, RPE\n"
    "      --max-dt S        stamp matching tolerance (default 0.001 s)\n"
    "      --rpe-delta S     RPE time step (default 1.0 s)\n"
    "  -h, --help            this text\n"
    "Stamps that do not match are counted and reported. Exit 1 on unreadable input.\n";

int usageError(const std::string& m) {
    std::fprintf(stderr, "kfd-eval: %s\nTry 'kfd-eval --help'.\n", m.c_str());
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::string est_file, rel_file, gt_file;
    double max_dt = 1e-3, rpe_delta = 1.0;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
        if (a == "-h" || a == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (a == "-r" || a == "--relations" || a == "-g" || a == "--gt" || a == "--max-dt" ||
                   a == "--rpe-delta") {
            const char* v = next();
            if (!v) return usageError(a + " needs a value");
            try {
                if (a == "-r" || a == "--relations")
                    rel_file = v;
                else if (a == "-g" || a == "--gt")
                    gt_file = v;
                else if (a == "--max-dt")
                    max_dt = std::stod(v);
                else
                    rpe_delta = std::stod(v);
            } catch (const std::exception& e) {
                return usageError(a + ": " + e.what());
            }
        } else if (!a.empty() && a[0] == '-') {
            return usageError("unknown option '" + a + "'");
        } else if (est_file.empty()) {
            est_file = a;
        } else {
            return usageError("too many arguments");
        }
    }
    if (est_file.empty()) return usageError("no estimated trajectory");
    if (rel_file.empty() && gt_file.empty()) return usageError("give --relations and/or --gt");
    try {
        auto est = kfd::readTum(est_file);
        kfd::sortByTime(est);
        std::printf("estimate   %s (%zu poses)\n", est_file.c_str(), est.size());
        if (!rel_file.empty()) {
            const auto r = kfd::evaluateRelations(est, kfd::readRelations(rel_file), max_dt);
            std::printf("relations  %s: %zu used, %zu unmatched (max dt %.3g s)\n",
                        rel_file.c_str(), r.used, r.unmatched, max_dt);
            std::printf("  trans abs  %.4f +- %.4f m    | trans sq %.5f +- %.5f m^2\n",
                        r.trans_mean, r.trans_std, r.trans2_mean, r.trans2_std);
            std::printf("  rot   abs  %.3f +- %.3f deg  | rot sq %.3f +- %.3f deg^2\n",
                        r.rot_mean_deg, r.rot_std_deg, r.rot2_mean, r.rot2_std);
        }
        if (!gt_file.empty()) {
            auto gt = kfd::readTum(gt_file);
            kfd::sortByTime(gt);
            const auto a = kfd::computeAte(est, gt, max_dt);
            std::printf(
                "ATE        %zu matched, %zu unmatched: RMSE %.4f m, mean %.4f m, max %.4f "
                "m\n",
                a.matched, a.unmatched, a.rmse, a.mean, a.max);
            const auto p = kfd::computeRpe(est, gt, rpe_delta, max_dt);
            std::printf(
                "RPE        %.2f s: %zu pairs, %zu unmatched: trans RMSE %.4f m, rot RMSE "
                "%.3f deg\n",
                rpe_delta, p.pairs, p.unmatched, p.trans_rmse, p.rot_rmse_deg);
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "kfd-eval: %s\n", e.what());
        return 1;
    }
    return 0;
}
