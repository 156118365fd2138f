#include "icp_verdicts.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

namespace kfd::icp_slam {

std::optional<IcpLogVerdict> parseIcpLogLine(std::string_view msg) {
    const auto number_after = [&](std::string_view key) -> std::optional<double> {
        const auto at = msg.find(key);
        if (at == std::string_view::npos) return std::nullopt;
        const std::string rest(msg.substr(at + key.size(), 32));
        char* end = nullptr;
        const double v = std::strtod(rest.c_str(), &end);
        if (end == rest.c_str() || !std::isfinite(v)) return std::nullopt;
        return v / 100.0;
    };
    if (const auto fit = number_after("Fit:")) return IcpLogVerdict{*fit, false};
    if (const auto low = number_after("Ignoring ICP of low quality:"))
        return IcpLogVerdict{*low, true};
    return std::nullopt;
}

IcpVerdicts::Verdict IcpVerdicts::count(IcpSlamSummary& sum) {
    ++sum.icp_runs;
    goodness_.push_back(current_->goodness);
    if (!current_->rejected) {
        gap_.accepted(current_->goodness);
        return Verdict::Accepted;
    }
    if (current_->goodness > min_goodness_) {
        ++sum.gap_checks_failed;
        return Verdict::GapCheckFailed;
    }
    ++sum.icp_rejected;
    return Verdict::Rejected;
}

std::optional<double> IcpVerdicts::median() const {
    if (goodness_.empty()) return std::nullopt;
    std::vector<double> g = goodness_;
    std::nth_element(g.begin(), g.begin() + static_cast<std::ptrdiff_t>(g.size() / 2), g.end());
    return g[g.size() / 2];
}

}  // namespace kfd::icp_slam
