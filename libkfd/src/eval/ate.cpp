#include "kfd/eval/ate.h"

#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "kfd/pipeline/format.h"

namespace kfd {
namespace {

void checkMaxDt(double max_dt) {
    if (!(max_dt >= 0.0) || !std::isfinite(max_dt))
        throw EvalError("max_dt must be finite and >= 0 (got " + std::to_string(max_dt) + " s)",
                        "max_dt");
}

}  // namespace

AteResult computeAte(const Trajectory& est, const Trajectory& gt, double max_dt) {
    checkMaxDt(max_dt);
    AteResult res;
    std::vector<Eigen::Vector2d> a, b;  // estimate, ground truth
    for (const auto& p : est) {
        const auto j = nearest(gt, p.t, max_dt);
        if (!j) {
            ++res.unmatched;
            continue;
        }
        a.emplace_back(p.pose.x, p.pose.y);
        b.emplace_back(gt[*j].pose.x, gt[*j].pose.y);
    }
    res.matched = a.size();
    if (a.size() < 2)
        throw EvalError("ATE needs at least 2 matched poses (" + std::to_string(a.size()) + " of " +
                        std::to_string(est.size()) + " matched within " + std::to_string(max_dt) +
                        " s)");
    // A ground truth that covers less than half of the estimate is another log's (or its
    // stamps are shifted): an RMSE over the few poses that happen to match would mislead.
    if (2 * res.matched < est.size())
        throw EvalError("ATE: only " + std::to_string(res.matched) + " of " +
                        std::to_string(est.size()) +
                        " estimated poses have a ground-truth pose within " + format("%g", max_dt) +
                        " s (" + std::to_string(res.unmatched) +
                        " unmatched): the ground truth must cover at least half of the "
                        "trajectory (another log's ground truth, or a larger --max-dt?)");
    // Umeyama without scale: R, t minimising sum |b - (R a + t)|^2.
    Eigen::Vector2d ma = Eigen::Vector2d::Zero(), mb = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < a.size(); ++i) {
        ma += a[i];
        mb += b[i];
    }
    ma /= static_cast<double>(a.size());
    mb /= static_cast<double>(b.size());
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (std::size_t i = 0; i < a.size(); ++i) cov += (b[i] - mb) * (a[i] - ma).transpose();
    // In 2D the optimal rotation angle is atan2 of the cross/dot sums.
    const double phi = std::atan2(cov(1, 0) - cov(0, 1), cov(0, 0) + cov(1, 1));
    const Eigen::Rotation2Dd rot(phi);
    const Eigen::Vector2d t = mb - rot * ma;
    res.alignment = Pose2D{t.x(), t.y(), phi};
    double sum2 = 0, sum = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const double e = (b[i] - (rot * a[i] + t)).norm();
        sum2 += e * e;
        sum += e;
        res.max = std::max(res.max, e);
    }
    res.rmse = std::sqrt(sum2 / static_cast<double>(a.size()));
    res.mean = sum / static_cast<double>(a.size());
    return res;
}

RpeResult computeRpe(const Trajectory& est, const Trajectory& gt, double delta_s, double max_dt) {
    checkMaxDt(max_dt);
    if (!(delta_s > 0.0) || !std::isfinite(delta_s))
        throw EvalError(
            "the RPE step must be finite and > 0 (got " + std::to_string(delta_s) + " s)",
            "delta_s");
    RpeResult res;
    double st = 0, sr = 0;
    std::size_t j = 0;
    for (std::size_t i = 0; i < gt.size(); ++i) {
        if (j < i) j = i;
        while (j < gt.size() && gt[j].t < gt[i].t + delta_s) ++j;
        if (j >= gt.size()) break;
        const auto ei = nearest(est, gt[i].t, max_dt);
        const auto ej = nearest(est, gt[j].t, max_dt);
        if (!ei || !ej) {
            ++res.unmatched;
            continue;
        }
        const Pose2D dg = between(gt[i].pose, gt[j].pose);
        const Pose2D de = between(est[*ei].pose, est[*ej].pose);
        const Pose2D e = between(dg, de);
        st += e.x * e.x + e.y * e.y;
        const double r = e.phi * 180.0 / kPi;
        sr += r * r;
        ++res.pairs;
    }
    if (res.pairs == 0)
        throw EvalError("RPE: no pose pair " + std::to_string(delta_s) +
                        " s apart matched the estimate within " + std::to_string(max_dt) + " s");
    {
        res.trans_rmse = std::sqrt(st / static_cast<double>(res.pairs));
        res.rot_rmse_deg = std::sqrt(sr / static_cast<double>(res.pairs));
    }
    return res;
}

}  // namespace kfd
