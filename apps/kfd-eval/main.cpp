// kfd-eval: trajectory error against ground truth (relations metric, ATE, RPE).
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

#include "common/cli.h"
#include "common/ground_truth_cli.h"
#include "kfd/eval/ate.h"
#include "kfd/eval/relations.h"
#include "kfd/pipeline/format.h"

namespace {

// What the command line sets.
struct Args {
    std::string est_file;
    kfd::app::GroundTruthArgs gt;
    double max_dt = 1e-3, rpe_delta = 1.0;
    std::optional<double> split_s;
};

void addOptions(kfd::app::Cli& cli, Args& a) {
    cli.option("EST.tum", a.est_file, "estimated trajectory (TUM)")->required();
    kfd::app::addGroundTruthOptions(
        cli, a.gt,
        "relations file only: Kuemmerle et al. 2009 relations metric\n"
        "(mean +- std of the translation error in m and rotation error\n"
        "in deg, absolute and squared)",
        "ground-truth TUM trajectory only: ATE RMSE after SE(2)\nalignment, RPE");
    cli.option("--max-dt", a.max_dt, "stamp matching tolerance (s)")
        ->type_name("S")
        ->capture_default_str();
    cli.option("--rpe-delta", a.rpe_delta, "RPE time step (s)")
        ->type_name("S")
        ->capture_default_str();
    cli.option("--split-seconds", a.split_s,
               "also the relations error of local relations (stamps at most S s\n"
               "apart) and of the long ones",
               kfd::app::toNumber<double>)
        ->type_name("S");
}

// A ground truth given, an estimate that is not a relations file, tolerances in range.
void checkArgs(const Args& a, const std::string& rel_file, const std::string& gt_file) {
    if (rel_file.empty() && gt_file.empty())
        throw kfd::app::UsageError("give a ground truth: -g FILE (or --relations, --gt)");
    if (const auto g = kfd::detectGroundTruthFormat(a.est_file);
        g.format == kfd::GroundTruthFormat::Relations)
        throw kfd::app::UsageError("EST.tum: " + a.est_file + " is " + kfd::toString(g.format) +
                                   ", not an estimated TUM trajectory (" + g.evidence() +
                                   "): give it with -g or --relations");
    if (!(a.max_dt >= 0.0) || !std::isfinite(a.max_dt))
        throw kfd::app::UsageError("--max-dt: must be finite and >= 0 (got " +
                                   std::to_string(a.max_dt) + ")");
    if (!(a.rpe_delta > 0.0) || !std::isfinite(a.rpe_delta))
        throw kfd::app::UsageError("--rpe-delta: must be finite and > 0 (got " +
                                   std::to_string(a.rpe_delta) + ")");
}

// --split-seconds: needs a relations file, finite and >= 0.
void checkSplit(const Args& a, const std::string& rel_file) {
    if (a.split_s && rel_file.empty())
        throw kfd::app::UsageError("--split-seconds needs a relations file (-g or --relations)");
    if (a.split_s && (!(*a.split_s >= 0.0) || !std::isfinite(*a.split_s)))
        throw kfd::app::UsageError("--split-seconds: must be finite and >= 0 (got " +
                                   std::to_string(*a.split_s) + ")");
}

// The relations error, all, then local and long with --split-seconds.
void printRelations(const kfd::Trajectory& est, const std::string& rel_file, const Args& a) {
    const double max_dt = a.max_dt;
    const auto relations = kfd::readRelations(rel_file);
    const auto r = kfd::evaluateRelations(est, relations, max_dt);
    std::printf("relations  %s: %zu used, %zu unmatched (max dt %.3g s)\n", rel_file.c_str(),
                r.used, r.unmatched, max_dt);
    std::printf("  trans abs  %.4f +- %.4f m    | trans sq %.5f +- %.5f m^2\n", r.trans_mean,
                r.trans_std, r.trans2_mean, r.trans2_std);
    std::printf("  rot   abs  %.3f +- %.3f deg  | rot sq %.3f +- %.3f deg^2\n", r.rot_mean_deg,
                r.rot_std_deg, r.rot2_mean, r.rot2_std);
    if (!a.split_s) return;
    const auto split = kfd::splitRelations(relations, *a.split_s);
    for (const auto& [name, sub] :
         {std::pair{"local", &split.local}, std::pair{"long", &split.far}}) {
        const char* cmp = sub == &split.local ? "<=" : "> ";
        if (sub->empty()) {
            std::printf("  %-5s (%s %g s): no relation\n", name, cmp, *a.split_s);
            continue;
        }
        // A subset that matched nothing is an error, like the whole set.
        const auto e = kfd::evaluateRelations(est, *sub, max_dt);
        std::printf(
            "  %-5s (%s %g s): %zu used, %zu unmatched: trans %.4f +- %.4f m, rot "
            "%.3f +- %.3f deg\n",
            name, cmp, *a.split_s, e.used, e.unmatched, e.trans_mean, e.trans_std, e.rot_mean_deg,
            e.rot_std_deg);
    }
}

// ATE and RPE against a ground-truth trajectory.
void printAte(const kfd::Trajectory& est, const std::string& gt_file, const Args& a) {
    auto gt = kfd::readTum(gt_file);
    kfd::sortByTime(gt);
    const auto at = kfd::computeAte(est, gt, a.max_dt);
    std::printf("ATE        %zu matched, %zu unmatched: RMSE %.4f m, mean %.4f m, max %.4f m\n",
                at.matched, at.unmatched, at.rmse, at.mean, at.max);
    const auto p = kfd::computeRpe(est, gt, a.rpe_delta, a.max_dt);
    std::printf("RPE        %.2f s: %s, %zu unmatched: trans RMSE %.4f m, rot RMSE %.3f deg\n",
                a.rpe_delta, kfd::plural(p.pairs, "pair").c_str(), p.unmatched, p.trans_rmse,
                p.rot_rmse_deg);
}

void run(Args& a) {
    std::string rel_file, gt_file;
    kfd::app::resolveGroundTruth(a.gt, rel_file, gt_file);
    checkArgs(a, rel_file, gt_file);
    auto est = kfd::readTum(a.est_file);
    kfd::sortByTime(est);
    std::printf("estimate   %s (%s)\n", a.est_file.c_str(),
                kfd::plural(est.size(), "pose").c_str());
    checkSplit(a, rel_file);
    if (!rel_file.empty()) printRelations(est, rel_file, a);
    if (!gt_file.empty()) printAte(est, gt_file, a);
}

}  // namespace

int main(int argc, char** argv) {
    kfd::app::Cli cli(
        "kfd-eval", "EST.tum [-g GT.relations] [-g GT.tum] [options]",
        "Trajectory error of EST.tum (TUM format) against ground truth: a relations file\n"
        "and/or a TUM trajectory, each told by its content.",
        "Stamps that do not match are counted and reported; a TUM ground truth that matches\n"
        "fewer than half of the estimate's poses is an error. Exit 1 on unreadable input, 2 on\n"
        "bad usage (a file given under the option of the other format included).");
    Args a;
    addOptions(cli, a);
    return cli.run(argc, argv, [&] { run(a); });
}
