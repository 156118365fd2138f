// Synthetic scans for the benchmarks: a ray-cast office floor (corridor + room with furniture)
// seen by a 1081-beam, 270-degree, 30 m scanner (the class of the paper's MIT data), with range
// noise, spikes, clutter and dropouts. Deterministic: scan k of a seed is always the same.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include <mrpt/obs/CObservation2DRangeScan.h>

#include "kfd/algorithms/keyframe_selector.h"
#include "kfd/algorithms/scan_tracker.h"
#include "kfd/paper/distance_filter.h"
#include "kfd/pipeline/pipeline.h"
#include "kfd/pipeline/scan.h"
#include "kfd/stages/core_stages.h"

namespace kfd {
namespace bench {

constexpr std::size_t kBeams = 1081;        // 0.25 deg steps over 270 deg
constexpr double kAperture = 1.5 * kPi;     // 270 deg
constexpr double kMaxRange = 30.0;          // m
constexpr double kScanRate = 40.0;          // Hz, the paper's MIT data
constexpr double kSpeed = 0.752;            // m/s, the paper's faster setting
constexpr unsigned kSeed = 20230101;        // every benchmark uses this seed
constexpr std::size_t kKeyframeScans = 16;  // distinct poses of the "keyframe kept" set
constexpr std::size_t kDroppedScans = 16;   // stream scans of the "keyframe dropped" set
constexpr std::size_t kLoopKeyframes = 32;  // keyframes around the loop (temporal evidence)

inline ScanGeometry mitGeometry() { return ScanGeometry{kBeams, kAperture, true}; }

/// Pipeline parameters of share/kfd/paper-mit-0.752.ini: m = 8, n = 20, P_pair = 0.985, guards
/// off, reference clustering (t = 5 rings, theta = 10 x resolution, m_threshold = 10).
inline Pipeline::Params paperParams(DenoiseVariant variant = DenoiseVariant::Reference) {
    Pipeline::Params p;
    p.stages = {"distance", "keyframe", stageName(variant)};
    p.get<DistanceStage>().min_range = 0.1;
    p.get<DistanceStage>().max_range = kMaxRange;
    p.get<KeyframeStage>().bins = 20;
    p.get<KeyframeStage>().window = 8;
    p.get<KeyframeStage>().p_pair = 0.985;
    p.get<KeyframeStage>().max_consecutive_drops = 0;
    p.get<KeyframeStage>().max_interval_s = 0.0;
    p.get<KeyframeStage>().max_translation_m = 0.0;
    p.get<KeyframeStage>().max_rotation_deg = 0.0;
    return p;
}

/// A 2D floor plan made of wall segments, and a ray caster over it.
class IndoorScene {
  public:
    struct Segment {
        double x0, y0, x1, y1;
    };

    void wall(double x0, double y0, double x1, double y1) { seg_.push_back({x0, y0, x1, y1}); }
    void box(double x0, double y0, double x1, double y1) {
        wall(x0, y0, x1, y0);
        wall(x1, y0, x1, y1);
        wall(x1, y1, x0, y1);
        wall(x0, y1, x0, y0);
    }

    /// A 45 m corridor (2.4 m wide, an alcove, a bin, a radiator) with a door into a
    /// 10 x 7 m room holding a table (four 5 cm legs), two chairs (4 cm legs), a pillar,
    /// a bookshelf and a cabinet. Looking down the corridor exceeds 30 m (no return).
    static IndoorScene officeFloor() {
        IndoorScene s;
        // Corridor, y in [-1.2, 1.2], x in [-5, 40].
        s.wall(-5, -1.2, 19.5, -1.2);
        s.wall(20.5, -1.2, 40, -1.2);
        s.wall(19.5, -1.2, 19.5, -2.6);  // alcove
        s.wall(19.5, -2.6, 20.5, -2.6);
        s.wall(20.5, -2.6, 20.5, -1.2);
        s.wall(-5, 1.2, 10, 1.2);  // door into the room at x in [10, 11]
        s.wall(11, 1.2, 40, 1.2);
        s.wall(-5, -1.2, -5, 1.2);
        s.wall(40, -1.2, 40, 1.2);
        s.box(25.0, -1.15, 25.3, -0.85);  // bin
        s.box(30.0, -1.2, 32.0, -1.1);    // radiator
        // Room, x in [6, 16], y in [1.2, 8.2].
        s.wall(6, 1.2, 6, 8.2);
        s.wall(6, 8.2, 16, 8.2);
        s.wall(16, 8.2, 16, 1.2);
        for (const double x : {8.5, 10.05})
            for (const double y : {4.5, 5.25}) s.box(x, y, x + 0.05, y + 0.05);  // table legs
        for (const double x : {8.7, 9.1})
            for (const double y : {3.8, 4.2}) s.box(x, y, x + 0.04, y + 0.04);  // chair
        for (const double x : {9.9, 10.3})
            for (const double y : {5.7, 6.1}) s.box(x, y, x + 0.04, y + 0.04);  // chair
        s.box(14.4, 2.0, 14.8, 2.4);                                            // pillar
        s.box(7.0, 7.8, 10.0, 8.2);                                             // bookshelf
        s.box(14.8, 6.0, 16.0, 7.5);                                            // cabinet
        return s;
    }

    /// Distance (m) from (x, y) along direction a to the nearest wall, +inf when none.
    double cast(double x, double y, double a) const {
        const double dx = std::cos(a), dy = std::sin(a);
        double best = std::numeric_limits<double>::infinity();
        for (const auto& g : seg_) {
            const double ex = g.x1 - g.x0, ey = g.y1 - g.y0;
            const double den = dx * ey - dy * ex;
            if (std::abs(den) < 1e-12) continue;
            const double wx = g.x0 - x, wy = g.y0 - y;
            const double t = (wx * ey - wy * ex) / den;
            const double u = (wx * dy - wy * dx) / den;
            if (t > 1e-9 && u >= 0.0 && u <= 1.0 && t < best) best = t;
        }
        return best;
    }

  private:
    std::vector<Segment> seg_;
};

/// Sensor imperfections, per beam.
struct ScanNoise {
    double sigma_m = 0.01;        // Gaussian range noise
    double spike_prob = 0.01;     // a one-beam return short of the wall (dust, mixed pixel)
    double clutter_prob = 0.002;  // a burst of 2-4 beams at a random range
    double dropout_prob = 0.003;  // no return (dark or specular surface)
};

/// Simulates scan `index` of stream `seed` at `pose`. Beams without a return within
/// kMaxRange are invalid and hold kMaxRange, as MRPT drivers store them.
inline Scan simulateScan(const IndoorScene& scene, const Pose2D& pose, unsigned seed,
                         std::size_t index, const ScanNoise& noise = {}) {
    std::mt19937 rng(seed * 1000003u + static_cast<unsigned>(index));
    std::normal_distribution<double> gauss(0.0, noise.sigma_m);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Scan s;
    s.geometry = mitGeometry();
    s.range.assign(kBeams, static_cast<float>(kMaxRange));
    s.valid.assign(kBeams, 0);
    s.timestamp = static_cast<double>(index) / kScanRate;
    s.odometry = pose;
    std::size_t clutter_left = 0;
    double clutter_range = 0.0;
    for (std::size_t i = 0; i < kBeams; ++i) {
        const double truth = scene.cast(pose.x, pose.y, pose.phi + s.geometry.angle(i));
        double r = truth + gauss(rng);
        const double u = unit(rng);
        if (clutter_left > 0) {
            --clutter_left;
            r = clutter_range + gauss(rng);
        } else if (u < noise.clutter_prob) {
            clutter_left = 1 + static_cast<std::size_t>(unit(rng) * 3.0);
            clutter_range = 0.3 + unit(rng) * 5.0;
            r = clutter_range;
        } else if (u < noise.clutter_prob + noise.spike_prob) {
            r = 0.2 + unit(rng) * 0.7 * std::min(truth, kMaxRange);
        } else if (u < noise.clutter_prob + noise.spike_prob + noise.dropout_prob) {
            continue;
        }
        if (!(r < kMaxRange)) continue;
        s.range[i] = static_cast<float>(r);
        s.valid[i] = 1;
    }
    return s;
}

/// The robot's path at the paper's speed and rate: a loop of radius 1.8 m in the room,
/// 1.88 cm and 0.6 deg per scan.
inline Pose2D loopPose(std::size_t index) {
    constexpr double cx = 12.0, cy = 4.6, radius = 1.8;
    const double a = -0.5 * kPi + kSpeed / radius * static_cast<double>(index) / kScanRate;
    return Pose2D{cx + radius * std::cos(a), cy + radius * std::sin(a), a + 0.5 * kPi};
}

/// The scans every benchmark runs on, after Algorithm 1 (so the pipeline's distance stage
/// changes nothing and every variant sees the same points).
struct Scenario {
    /// kKeyframeScans scans from distinct poses (room and corridor, headings 0-315 deg): cycled
    /// through an m = 8 window, each one is a keyframe. The "keyframe kept" path, DBSCAN and
    /// the denoisers run on these.
    std::vector<Scan> keyframes;
    /// The first scans of the loop stream: fed to a fresh selector they fill its m = 8 window.
    std::vector<Scan> prefix;
    /// Later scans of the stream that the window primed by `prefix` drops (the selector's
    /// state does not change on a drop, so they can be replayed in any order).
    std::vector<Scan> dropped;
    /// kLoopKeyframes keyframes evenly around the loop (0.35 m and 11.25 deg apart, with
    /// odometry), closing the circle: the evidence denoiser, cycled through them, always has
    /// its previous keyframe (temporal evidence on every call).
    std::vector<Scan> loop_keyframes;
    /// The stream scan just before each loop keyframe (1.88 cm and 0.6 deg back): what the
    /// keyframe stage dropped last, the evidence denoiser's temporal_scans reference.
    std::vector<Scan> loop_before;
    /// The stream scan just after each loop keyframe: the next_scan reference (issue 25).
    std::vector<Scan> loop_after;
};

inline Scenario makeScenario(unsigned seed = kSeed) {
    const IndoorScene scene = IndoorScene::officeFloor();
    const Pipeline::Params params = paperParams();
    const DistanceFilter distance(params.get<DistanceStage>());
    Scenario sc;

    const Pose2D places[] = {{12.0, 4.6, 0.0}, {3.0, 0.0, 0.3}, {8.0, 3.0, 0.6}, {20.0, 0.2, 0.9}};
    for (std::size_t k = 0; k < kKeyframeScans; ++k) {
        Pose2D p = places[k % 4];
        p.phi += 0.5 * kPi * static_cast<double>(k / 4) + 0.25 * kPi * static_cast<double>(k % 2);
        Scan s = simulateScan(scene, p, seed + 1, k);
        distance.filter(s);
        sc.keyframes.push_back(std::move(s));
    }

    KeyframeSelector selector(params.get<KeyframeStage>());
    std::size_t i = 0;
    for (; selector.windowSize() < params.get<KeyframeStage>().window; ++i) {
        if (i > 20000) throw std::runtime_error("bench scenario: the window never fills");
        Scan s = simulateScan(scene, loopPose(i), seed, i);
        distance.filter(s);
        selector.filter(s);
        sc.prefix.push_back(std::move(s));
    }
    for (const std::size_t end = i + 2000; sc.dropped.size() < kDroppedScans && i < end; ++i) {
        Scan s = simulateScan(scene, loopPose(i), seed, i);
        distance.filter(s);
        KeyframeSelector probe = selector;
        if (!probe.filter(s).keyframe) sc.dropped.push_back(std::move(s));
    }
    if (sc.dropped.empty()) throw std::runtime_error("bench scenario: no scan is dropped");
    // One turn of the loop takes 2 pi radius / (speed / rate) scans.
    const double per_turn = 2.0 * kPi * 1.8 / (kSpeed / kScanRate);
    for (std::size_t k = 0; k < kLoopKeyframes; ++k) {
        const auto index = static_cast<std::size_t>(per_turn * static_cast<double>(k) /
                                                    static_cast<double>(kLoopKeyframes));
        Scan s = simulateScan(scene, loopPose(index), seed + 2, index);
        distance.filter(s);
        sc.loop_keyframes.push_back(std::move(s));
        const std::size_t before = index > 0 ? index - 1 : static_cast<std::size_t>(per_turn) - 1;
        Scan b = simulateScan(scene, loopPose(before), seed + 2, before);
        distance.filter(b);
        sc.loop_before.push_back(std::move(b));
        Scan a = simulateScan(scene, loopPose(index + 1), seed + 2, index + 1);
        distance.filter(a);
        sc.loop_after.push_back(std::move(a));
    }
    return sc;
}

/// kfd's view selector with every threshold out of reach: each call measures the scan against
/// the keyframe and drops it, so the keyframe never changes (the cost of a dropped scan's
/// decision; a keyframe adds one copy of the sampled ranges).
inline ViewKeyframeSelector::Params viewParamsThatDrop() {
    ViewKeyframeSelector::Params p;
    p.max_consecutive_drops = 0;
    p.max_interval_s = 0.0;
    p.max_translation_m = 0.0;
    p.max_rotation_deg = 0.0;
    p.view.max_view_change = 1e3;
    p.view.max_changed_fraction = 1.0;
    p.view.change_tolerance_m = 1e3;
    p.view.corridor_translation_m = 1e6;
    p.view.corridor_rotation_deg = 360.0;
    p.view.corridor_interval_s = 1e6;
    return p;
}

/// A denoising stage called as a filter (what the benchmarks time): its DenoiseResult, with
/// the sensor's next scan when given (the evidence stage's next_scan).
template <class S>
class StageFilter {
  public:
    explicit StageFilter(const typename S::Params& p) : stage_(p) {}
    DenoiseResult filter(Scan& scan, const Scan* next = nullptr) {
        StageReport report;
        stage_.finish(scan, report, chain(scan), next);
        return *report.diagnostics<DenoiseResult>();
    }
    void observe(const Scan& scan) { stage_.observeDropped(scan, chain(scan)); }
    /// From now on the chain before the stage holds a track stage that tracked every scan at
    /// its odometry (the simulated scans' true pose), with this RMS residual (m).
    void trackAtOdometry(float rms_m) {
        tracked_ = true;
        track_.verdict = TrackVerdict::Tracked;
        track_.rms_m = rms_m;
    }

  private:
    const ScanReport& chain(const Scan& scan) {
        if (!tracked_ || !scan.odometry) return chain_;
        track_.pose = *scan.odometry;
        tracked_chain_.stage_reports[0].setDiagnostics(track_);
        tracked_chain_.stage_count = 1;
        return tracked_chain_;
    }
    S stage_;
    ScanReport chain_{};
    bool tracked_ = false;
    TrackResult track_;
    ScanReport tracked_chain_{};
};

/// The MRPT form of a core scan (what a driver gives the door).
inline mrpt::obs::CObservation2DRangeScan toMrpt(const Scan& s) {
    mrpt::obs::CObservation2DRangeScan o;
    o.sensorLabel = "LASER";
    o.aperture = static_cast<float>(s.geometry.aperture);
    o.rightToLeft = s.geometry.right_to_left;
    o.resizeScan(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        o.setScanRange(i, s.range[i]);
        o.setScanRangeValidity(i, s.valid[i] != 0);
    }
    o.timestamp = mrpt::Clock::fromDouble(s.timestamp);
    return o;
}

/// The scan without its odometry (what a robot without wheel encoders gives the selector).
inline Scan laserOnly(Scan s) {
    s.odometry.reset();
    return s;
}

/// Restores the valid flags of `work` from `pristine` (what a stage invalidated last time).
inline void restoreValid(const Scan& pristine, Scan& work) {
    std::copy(pristine.valid.begin(), pristine.valid.end(), work.valid.begin());
}

}  // namespace bench
}  // namespace kfd
