// libFuzzer target: the core pipeline (default stage registry: the paper's stages, kfd's and
// the baselines; kfd's default pipeline unless a key changes it) fed arbitrary parameters and a
// stream of arbitrary scans.
//
// Input layout (FuzzedDataProvider): up to 8 key = value pairs set through the config layer
// (kfd::applyConfigKey, the key picked from kfd::configKeys()), then up to 8 scans through one
// Pipeline (so the keyframe window and the other stream state are exercised). Each scan:
// beam count (0-2048), aperture and ranges either picked from the special values (0, NaN,
// +-inf, negative, > 2 pi, huge) or arbitrary doubles, valid flags, stamp, odometry.
// kfd::Error is an accepted outcome (bad parameters, bad scans); anything else (a crash, a
// sanitizer report, another exception) is a finding.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "kfd/mrpt/config.h"
#include "kfd/mrpt/default_stages.h"
#include "kfd/pipeline/error.h"
#include "kfd/pipeline/pipeline.h"

namespace {

double special(FuzzedDataProvider& in) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    static const double kValues[] = {0.0,  std::nan(""), kInf,         -kInf, -1.0, 1e-12, 1e300,
                                     -0.0, kfd::kPi,     2 * kfd::kPi, 7.0,   1.0,  0.5};
    if (in.ConsumeBool()) return kValues[in.ConsumeIntegralInRange<std::size_t>(0, 12)];
    return in.ConsumeFloatingPoint<double>();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    const auto& registry = kfd::defaultStageRegistry();
    const auto& keys = kfd::configKeys();
    kfd::Pipeline::Params params = kfd::kfdDefaults();  // kfd's default pipeline (track too)
    const int n_keys = in.ConsumeIntegralInRange<int>(0, 8);
    for (int k = 0; k < n_keys; ++k) {
        const auto& key = keys[in.ConsumeIntegralInRange<std::size_t>(0, keys.size() - 1)];
        const std::string value = in.ConsumeRandomLengthString(24);
        try {
            kfd::applyConfigKey(params, key.name, value, registry);
        } catch (const kfd::Error&) {
        }
    }
    try {
        kfd::validateConfig(params, registry);
    } catch (const kfd::Error&) {
        return 0;  // the tools refuse such a configuration before any scan
    }
    kfd::Pipeline pipeline;
    try {
        pipeline.initialize(params, registry);
    } catch (const kfd::Error&) {
        return 0;
    }
    const int n_scans = in.ConsumeIntegralInRange<int>(1, 8);
    kfd::Scan scan;
    for (int s = 0; s < n_scans && in.remaining_bytes() > 0; ++s) {
        if (s == 0 || in.ConsumeBool()) {  // new geometry, else the previous one
            scan.geometry.beams = in.ConsumeIntegralInRange<std::size_t>(0, 2048);
            scan.geometry.aperture = special(in);
            scan.geometry.right_to_left = in.ConsumeBool();
        }
        const std::size_t beams = scan.geometry.beams;
        scan.range.assign(beams, 0.0f);
        scan.valid.assign(beams, 1);
        const int mode = in.ConsumeIntegralInRange<int>(0, 2);
        const float base = static_cast<float>(in.ConsumeFloatingPointInRange<double>(0.0, 80.0));
        for (std::size_t i = 0; i < beams; ++i) {
            if (mode == 0)  // smooth: a wall with a few outliers
                scan.range[i] = base + (in.ConsumeBool() ? 0.0f : static_cast<float>(special(in)));
            else if (mode == 1)
                scan.range[i] =
                    static_cast<float>(in.ConsumeFloatingPointInRange<double>(0.0, 80.0));
            else
                scan.range[i] = in.ConsumeFloatingPoint<float>();
            scan.valid[i] = in.ConsumeBool() ? 0 : 1;
        }
        scan.timestamp = special(in);
        if (in.ConsumeBool())
            scan.odometry = kfd::Pose2D{special(in), special(in), special(in)};
        else
            scan.odometry.reset();
        try {
            pipeline.process(scan);
        } catch (const kfd::Error&) {
        }
    }
    return 0;
}
