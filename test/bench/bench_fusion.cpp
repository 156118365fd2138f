// kfd_bench_fusion: fused keyframes (issue 25) on a real log. Runs kfd's defaults up to the
// keyframe stage (odometry_check, distance, keyframe), shows every dropped scan to a FuseStage
// and fuses each keyframe, then reports the range noise of the keyframes before and after
// fusion, measured as the evidence denoiser measures it (EvidenceFilter::lineResidual: each
// beam against the line through its two neighbours):
//   sigma_decile  the lower decile of |residual| over every beam of every keyframe,
//                 / (0.1257 sqrt(1.5)) (the evidence filter's estimate, pooled over the log)
//   med_line      the median |residual| over the line-like beams: |residual| before fusion
//                 <= 3 sqrt(1.5) sigma_decile(before) (the same beams after fusion)
// and the share of beams fused. Extra arguments KEY=VALUE set the fuse stage's keys
// (kfd-filter --list-keys), e.g. fuse_estimator=mean; max_log_scans=N stops after N scans.
//
// Instructions per dropped scan and per keyframe (deterministic, unlike wall time):
//   valgrind --tool=callgrind --callgrind-out-file=cg.out kfd_bench_fusion LOG
//   callgrind_annotate --inclusive=yes cg.out | grep kfd_fx_
// and divide by the dropped / keyframe counts the program prints.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "kfd/algorithms/evidence_filter.h"
#include "kfd/io/open_source.h"
#include "kfd/mrpt/config.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/stages/fuse_stage.h"

const kfd::ScanReport kNoChain{};  // a dropped scan's report: nothing the fuse stage reads

extern "C" {
__attribute__((noinline)) void kfd_fx_dropped(kfd::FuseStage& f, const kfd::Scan& s) {
    f.observeDropped(s, kNoChain);
}
__attribute__((noinline)) void kfd_fx_keyframe(kfd::FuseStage& f, kfd::Scan& s,
                                               kfd::StageReport& sr, const kfd::ScanReport& r) {
    f.process(s, sr, r);
}
}

namespace {

constexpr double kDecileScale = 0.1257 * 1.2247448713915889;  // decile of |N(0, 1.5 s^2)| / s

// |residual| of every beam with two valid neighbours, appended to out (NaN where there is none,
// so that before and after stay beam-aligned).
void residuals(const kfd::Scan& s, std::vector<float>& out) {
    const double cos_res = std::cos(s.geometry.resolution());
    for (std::size_t i = 1; i + 1 < s.size(); ++i) {
        float e = std::nanf("");
        if (s.valid[i - 1] && s.valid[i] && s.valid[i + 1])
            e = static_cast<float>(std::abs(kfd::EvidenceFilter::lineResidual(
                s.range[i - 1], s.range[i], s.range[i + 1], cos_res)));
        out.push_back(e);
    }
}

double quantile(std::vector<float> v, double q) {
    v.erase(std::remove_if(v.begin(), v.end(), [](float x) { return !std::isfinite(x); }), v.end());
    if (v.empty()) return 0.0;
    auto at = v.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
    std::nth_element(v.begin(), at, v.end());
    return *at;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr,
                     "usage: kfd_bench_fusion LOG [fuse_KEY=VALUE ...] [max_log_scans=N]\n");
        return 2;
    }
    kfd::FuseStage::Params fp;
    std::size_t max_log_scans = static_cast<std::size_t>(-1);
    const auto keys = kfd::FuseStage::keys();
    for (int a = 2; a < argc; ++a) {
        const std::string arg = argv[a];
        const auto eq = arg.find('=');
        const std::string k = arg.substr(0, eq),
                          v = eq == std::string::npos ? "" : arg.substr(eq + 1);
        if (k == "max_log_scans") {
            max_log_scans = std::stoul(v);
            continue;
        }
        const auto it =
            std::find_if(keys.begin(), keys.end(), [&](const auto& x) { return x.name == k; });
        if (it == keys.end()) {
            std::fprintf(stderr, "unknown key %s\n", k.c_str());
            return 2;
        }
        it->set(&fp, v);
    }
    kfd::Pipeline::Params pp = kfd::kfdDefaults();
    pp.stages = {"odometry_check", "distance", "keyframe"};
    kfd::Pipeline pipe(pp);
    kfd::FuseStage fuse(fp);
    auto src = kfd::openSource(argv[1]);
    kfd::SourceEntry e;
    kfd::Scan s;
    std::vector<float> before, after, raw;
    std::vector<std::uint8_t> changed;  // per residual: its beam was fused
    std::size_t scans = 0, dropped = 0, keyframes = 0, fused = 0, valid = 0, agreeing = 0;
    std::size_t used = 0, kept = 0, misaligned = 0;
    double sigma_sum = 0.0;
    while (scans < max_log_scans && src->next(e)) {
        e.forEachScan([&](const auto& obs) {
            if (scans >= max_log_scans) return;
            kfd::toCore(*obs, s);
            s.odometry = e.odometry;
            if (s.odometry && !kfd::finitePose(s.odometry->x, s.odometry->y, s.odometry->phi))
                s.odometry.reset();
            ++scans;
            kfd::ScanReport r;
            try {
                r = pipe.process(s);
            } catch (const kfd::ScanError&) {
                return;
            }
            if (!r.keep) {
                ++dropped;
                kfd_fx_dropped(fuse, s);
                return;
            }
            ++keyframes;
            residuals(s, before);
            raw = s.range;
            kfd::StageReport sr;
            kfd_fx_keyframe(fuse, s, sr, r);
            residuals(s, after);
            for (std::size_t i = 1; i + 1 < s.size(); ++i) changed.push_back(s.range[i] != raw[i]);
            const auto* d = sr.diagnostics<kfd::ScanFusion::Result>();
            fused += d->beams_fused;
            valid += d->beams_valid;
            agreeing += static_cast<std::size_t>(
                std::lround(d->mean_scans_per_fused * static_cast<double>(d->beams_fused)));
            used += d->scans_used;
            kept += d->scans_kept;
            misaligned += d->scans_misaligned;
            sigma_sum += d->sigma;
        });
    }
    const double sig_b = quantile(before, 0.1) / kDecileScale;
    const double sig_a = quantile(after, 0.1) / kDecileScale;
    std::vector<float> line_b, line_a, fused_b, fused_a, fline_b, fline_a;
    const float tol = static_cast<float>(3.0 * 1.2247448713915889 * sig_b);
    for (std::size_t i = 0; i < before.size(); ++i)
        if (std::isfinite(before[i]) && before[i] <= tol) {
            line_b.push_back(before[i]);
            line_a.push_back(after[i]);
            if (changed[i]) {
                fline_b.push_back(before[i]);
                fline_a.push_back(after[i]);
            }
        }
    for (std::size_t i = 0; i < before.size(); ++i)
        if (changed[i]) {
            fused_b.push_back(before[i]);
            fused_a.push_back(after[i]);
        }
    std::printf("log %s\nscans %zu dropped %zu keyframes %zu\n", argv[1], scans, dropped,
                keyframes);
    std::printf("fused_share %.4f beams_fused %zu of %zu valid; scans per fused beam %.2f\n",
                valid ? static_cast<double>(fused) / static_cast<double>(valid) : 0.0, fused, valid,
                fused ? static_cast<double>(agreeing) / static_cast<double>(fused) : 0.0);
    std::printf("dropped scans kept %zu used %zu misaligned %zu; mean sigma used %.4f m\n", kept,
                used, misaligned, keyframes ? sigma_sum / static_cast<double>(keyframes) : 0.0);
    std::printf("sigma_decile_m before %.5f after %.5f\n", sig_b, sig_a);
    std::printf("med_line_m before %.5f after %.5f (line-like beams %zu)\n", quantile(line_b, 0.5),
                quantile(line_a, 0.5), line_b.size());
    // The same on the fused beams only (the others are unchanged, or changed only through a
    // fused neighbour).
    std::printf(
        "fused beams: sigma_decile_m before %.5f after %.5f; med_line_m before %.5f "
        "after %.5f (%zu); med_all_m before %.5f after %.5f (%zu)\n",
        quantile(fused_b, 0.1) / kDecileScale, quantile(fused_a, 0.1) / kDecileScale,
        quantile(fline_b, 0.5), quantile(fline_a, 0.5), fline_b.size(), quantile(fused_b, 0.5),
        quantile(fused_a, 0.5), fused_b.size());
    return 0;
}
