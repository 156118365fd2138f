#include "kfd/filters/beam_count.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "kfd/pipeline/error.h"

namespace kfd {

void BeamCountResampler::initialize(const Params& p) {
    if (p.beams != 0 && (p.beams < kMinScanBeams || p.beams > kMaxScanBeams))
        throw ParameterError(
            "beams", "beam_count: beams must be 0 (the first scan's count) or in [" +
                         std::to_string(kMinScanBeams) + ", " + std::to_string(kMaxScanBeams) +
                         "], not " + std::to_string(p.beams));
    if (!(p.max_jump >= 0.0 && p.max_jump <= 1.0))
        throw ParameterError("max_jump", "beam_count: max_jump must be in [0, 1], not " +
                                             keys::formatReal(p.max_jump));
    params_ = p;
}

BeamCountResampler::Result BeamCountResampler::resample(Scan& scan, std::size_t beams,
                                                        Scan& out) const {
    Result r;
    const std::size_t n = scan.size();
    r.beams_in = n;
    r.beams_out = beams;
    r.points_in = scan.countValid();
    if (n == beams || n < kMinScanBeams) {  // nothing to resample (or nothing to resample from)
        r.beams_out = n;
        r.points_out = r.points_in;
        return r;
    }
    const bool has_intensity = scan.intensity.size() == n;
    out.range.resize(beams);
    out.valid.resize(beams);
    out.intensity.resize(has_intensity ? beams : 0);
    const double scale = static_cast<double>(n - 1) / static_cast<double>(beams - 1);
    for (std::size_t j = 0; j < beams; ++j) {
        const double u = std::min(static_cast<double>(j) * scale, static_cast<double>(n - 1));
        const auto i0 = static_cast<std::size_t>(u);
        const std::size_t i1 = std::min(i0 + 1, n - 1);
        const double t = u - static_cast<double>(i0);
        const float r0 = scan.range[i0], r1 = scan.range[i1];
        const bool one_surface = scan.valid[i0] && scan.valid[i1] &&
                                 std::fabs(r0 - r1) <= params_.max_jump * std::min(r0, r1);
        if (one_surface) {
            out.range[j] = static_cast<float>((1.0 - t) * r0 + t * r1);
            out.valid[j] = 1;
            if (has_intensity)
                out.intensity[j] =
                    static_cast<float>((1.0 - t) * scan.intensity[i0] + t * scan.intensity[i1]);
        } else {
            const std::size_t k = t < 0.5 ? i0 : i1;
            out.range[j] = scan.range[k];
            out.valid[j] = scan.valid[k];
            if (has_intensity) out.intensity[j] = scan.intensity[k];
        }
    }
    std::swap(scan.range, out.range);
    std::swap(scan.valid, out.valid);
    std::swap(scan.intensity, out.intensity);
    scan.geometry.beams = beams;
    r.points_out = scan.countValid();
    r.points_removed = r.points_in > r.points_out ? r.points_in - r.points_out : 0;
    r.resampled = 1;
    return r;
}

bool BeamCountStage::process(Scan& scan, StageReport& report, const ScanReport&) {
    if (target_ == 0) target_ = algo_.params().beams ? algo_.params().beams : scan.size();
    const auto r = algo_.resample(scan, target_, buffer_);
    report.points_removed = r.points_removed;
    report.setDiagnostics(r);
    return true;
}

ScanGeometry BeamCountStage::outputGeometry(const ScanGeometry& in) const {
    const std::size_t beams = target_ ? target_ : algo_.params().beams;
    ScanGeometry g = in;
    if (beams != 0 && in.beams >= kMinScanBeams) g.beams = beams;
    return g;
}

std::vector<StageKey> BeamCountStage::keys() {
    using P = Params;
    return {keys::count<P>("beam_count", "beams",
                           "beam_count: beams out, over each scan's own aperture (0: the first "
                           "scan's count)",
                           0, static_cast<double>(kMaxScanBeams),
                           [](P& p) -> std::size_t& { return p.beams; }),
            keys::real<P>("beam_count_max_jump", "max_jump",
                          "beam_count: neighbours within this share of the nearer range are "
                          "interpolated; farther apart, the nearer beam is taken as it is",
                          0, 1, false, [](P& p) -> double& { return p.max_jump; })};
}

std::vector<StageColumn> BeamCountStage::columns() {
    using R = BeamCountResampler::Result;
    return {diagnosticColumn<R>("beams_in", "the driver's beam count (before beam_count)", "%zu",
                                [](const R& r) { return r.beams_in; })};
}

std::vector<StageCounter> BeamCountStage::counters() {
    using R = BeamCountResampler::Result;
    return {diagnosticCounter<R>("scans_resampled", "scans whose beam count beam_count changed",
                                 false, [](const R& r) { return r.resampled; })};
}

}  // namespace kfd
