#include "kfd/sim/simulator.h"

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/poses/CPose2D.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "kfd/eval/trajectory.h"
#include "kfd/io/gz_output.h"
#include "kfd/mrpt/scan_adapter.h"
#include "kfd/os/cancel.h"
#include "kfd/os/output_paths.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = kPi / 180.0;

// The route as a sequence of primitive motions, sampled at a fixed rate.
struct Motion {
    enum Kind { TurnTo, Spin, Drive, Stop } kind;
    double value = 0;     // TurnTo: heading (rad); Spin: angle (rad); Stop: seconds
    double x = 0, y = 0;  // Drive: target (m)
};

std::vector<Motion> plan(const World& w) {
    std::vector<Motion> m;
    for (std::size_t i = 1; i < w.route.size(); ++i) {
        const auto& a = w.route[i - 1];
        const auto& b = w.route[i];
        m.push_back(Motion{Motion::TurnTo, std::atan2(b.y - a.y, b.x - a.x)});  // face the leg
        m.push_back(Motion{Motion::Drive, 0.0, b.x, b.y});
        if (b.stop_s > 0) m.push_back(Motion{Motion::Stop, b.stop_s});
        if (b.spin_deg != 0) m.push_back(Motion{Motion::Spin, b.spin_deg * kDeg});
    }
    return m;
}

// Ground-truth poses at `rate` Hz along the plan.
std::vector<Pose2D> sample(const World& w, double rate, double speed, double turn_rate,
                           double max_duration) {
    const auto motions = plan(w);
    const double dt = 1.0 / rate;
    Pose2D p{w.route[0].x, w.route[0].y,
             std::atan2(w.route[1].y - w.route[0].y, w.route[1].x - w.route[0].x)};
    std::vector<Pose2D> out{p};
    auto emit = [&]() {
        out.push_back(p);
        return max_duration <= 0 || static_cast<double>(out.size()) * dt < max_duration;
    };
    for (const auto& m : motions) {
        if (m.kind == Motion::TurnTo || m.kind == Motion::Spin) {
            double remaining = m.kind == Motion::Spin ? m.value : wrapAngle(m.value - p.phi);
            while (std::abs(remaining) > 1e-9) {
                const double step =
                    std::copysign(std::min(std::abs(remaining), turn_rate * dt), remaining);
                p.phi = wrapAngle(p.phi + step);
                remaining -= step;
                if (!emit()) return out;
            }
        } else if (m.kind == Motion::Drive) {
            for (;;) {
                const double dx = m.x - p.x, dy = m.y - p.y, d = std::hypot(dx, dy);
                if (d < 1e-9) break;
                const double s = std::min(d, speed * dt);
                p.x += s * dx / d;
                p.y += s * dy / d;
                if (!emit()) return out;
            }
        } else {
            for (int k = 0; k < static_cast<int>(std::round(m.value * rate)); ++k)
                if (!emit()) return out;
        }
    }
    return out;
}

}  // namespace

SensorModel sensorModel(const std::string& name) {
    if (name == "mit") return SensorModel{40.0, 1081, 270.0, 0.1, 30.0, 0.01};
    if (name == "gazebo") return SensorModel{10.0, 720, 359.5, 0.1, 12.0, 0.01};
    throw SimulationError("unknown sensor '" + name + "' (known: mit, gazebo)");
}

namespace {

// The four outputs' names, checked before anything is written: no output is an input or
// another output, and the rawlog is a .rawlog.
SimulationSummary outputNames(const SimulationOptions& o) {
    SimulationSummary sum;
    const fs::path out(o.output);
    const std::string stem = (out.parent_path() / out.stem()).string();
    sum.rawlog = o.output;
    sum.ground_truth = stem + ".gt.tum";
    sum.odometry = stem + ".odom.tum";
    sum.labels = stem + ".labels.csv";
    checkOutputPaths({{"gridmap", o.gridmap}, {"route", o.route}},
                     {{"output rawlog", sum.rawlog},
                      {"ground truth", sum.ground_truth},
                      {"odometry", sum.odometry},
                      {"labels", sum.labels}});
    if (!sum.rawlog.empty())
        checkOutputName({"output rawlog", sum.rawlog}, {".rawlog"},
                        "kfd-simulate writes an MRPT rawlog (.rawlog)");
    return sum;
}

// The simulated laser, as MRPT's scan whose ranges each step fills in.
mrpt::obs::CObservation2DRangeScan laserOf(const SensorModel& sensor) {
    mrpt::obs::CObservation2DRangeScan scan;
    scan.sensorLabel = "LASER";
    scan.aperture = static_cast<float>(sensor.fov_deg * kDeg);
    scan.maxRange = static_cast<float>(sensor.max_range);
    scan.rightToLeft = true;
    scan.stdError = static_cast<float>(sensor.range_sigma);
    return scan;
}

// One step's odometry: the true increment, corrupted (two draws of `gauss`); adds its length
// to the distance travelled.
void driftOdometry(const SimulationOptions& o, const Pose2D& from, const Pose2D& to,
                   std::mt19937& rng, std::normal_distribution<double>& gauss,
                   mrpt::poses::CPose2D& odo, double& distance_m) {
    const Pose2D d = between(from, to);
    const double len = std::hypot(d.x, d.y);
    const double f_t = 1.0 + o.odo_trans_sigma * gauss(rng);
    const double dphi =
        d.phi + o.odo_rot_sigma * std::abs(d.phi) * gauss(rng) + o.odo_drift_deg_per_m * kDeg * len;
    odo = odo + mrpt::poses::CPose2D(d.x * f_t, d.y * f_t, dphi);
    distance_m += len;
}

// The scan at the true pose: ray casting without MRPT's own noise (it draws from MRPT's
// global, unseeded random generator), then the range noise from our seeded generator, the
// sensor's range limits and the injected noise (`kinds`: what each beam became).
void simulateScan(World& world, const SensorModel& sensor, const Pose2D& pose,
                  mrpt::Clock::time_point stamp, std::mt19937& rng,
                  std::normal_distribution<double>& gauss, NoiseInjector& noise,
                  mrpt::obs::CObservation2DRangeScan& scan, Scan& core,
                  std::vector<NoiseKind>& kinds) {
    world.grid.laserScanSimulator(scan, mrpt::poses::CPose2D(pose.x, pose.y, pose.phi), 0.5f,
                                  sensor.beams, 0.0f);
    scan.timestamp = stamp;
    toCore(scan, core);
    for (std::size_t i = 0; i < core.size(); ++i)
        if (core.valid[i]) core.range[i] += static_cast<float>(sensor.range_sigma * gauss(rng));
    for (std::size_t i = 0; i < core.size(); ++i)
        if (core.valid[i] &&
            (core.range[i] < sensor.min_range || core.range[i] >= sensor.max_range))
            core.valid[i] = 0;
    noise.apply(core, kinds, rng);
    for (std::size_t i = 0; i < core.size(); ++i) {
        scan.setScanRange(i, core.range[i]);
        scan.setScanRangeValidity(i, core.valid[i] != 0);
    }
}

// The labels of scan k's noisy beams, counted by kind.
void writeLabels(OutputFile& labels, std::size_t k, double t, const std::vector<NoiseKind>& kinds,
                 SimulationSummary& sum) {
    for (std::size_t i = 0; i < kinds.size(); ++i) {
        if (kinds[i] == NoiseKind::Clean) continue;
        labels << std::to_string(k) + ',' + std::to_string(t) + ',' + std::to_string(i) + ',' +
                      toString(kinds[i]) + '\n';
        sum.noise_isolated += kinds[i] == NoiseKind::Isolated;
        sum.noise_clustered += kinds[i] == NoiseKind::Clustered;
        sum.noise_edge += kinds[i] == NoiseKind::Edge;
    }
}

// The world, sensor and noise the options name, checked: a SimulationError when they are bad.
void setUp(const SimulationOptions& o, World& world, SensorModel& sensor, NoiseInjector& noise) {
    try {
        world = o.gridmap.empty() ? makeWorld(o.world) : loadWorld(o.gridmap, o.route);
        sensor = sensorModel(o.sensor);
        noise.initialize(o.noise);
    } catch (const std::exception& e) {  // bad names, unreadable gridmap or route file
        throw SimulationError(e.what());
    }
    if (!(o.speed_mps > 0) || !(o.turn_rate_dps > 0))
        throw SimulationError("speed and turn rate must be > 0");
    if (o.output.empty()) throw SimulationError("no output rawlog given");
}

}  // namespace

SimulationSummary Simulator::run(const SimulationOptions& o) {
    SimulationSummary sum = outputNames(o);
    World world;
    SensorModel sensor;
    NoiseInjector noise;
    setUp(o, world, sensor, noise);
    const auto gt =
        sample(world, sensor.rate_hz, o.speed_mps, o.turn_rate_dps * kDeg, o.duration_s);
    std::mt19937 rng(o.seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    // Each output is written under a temporary name beside it and renamed once all four are
    // complete; every byte through kfd's checked writers (a full disk is a WriteError).
    const fs::path out(o.output);
    std::error_code mk;
    if (!out.parent_path().empty()) fs::create_directories(out.parent_path(), mk);
    TempOutputFile tmp(sum.rawlog), tmp_gt(sum.ground_truth), tmp_odo(sum.odometry),
        tmp_labels(sum.labels);
    GzOutputStream f(tmp.path(), sum.rawlog, 1);
    OutputFile labels(tmp_labels.path(), sum.labels);
    labels << "scan,timestamp,beam,kind\n";
    Trajectory gt_traj, odo_traj;
    mrpt::poses::CPose2D odo;  // drifting odometry, starts at the origin
    const double t0 = 1700000000.0;
    Scan core;
    std::vector<NoiseKind> kinds;
    mrpt::obs::CObservation2DRangeScan scan = laserOf(sensor);
    for (std::size_t k = 0; k < gt.size(); ++k) {
        throwIfCancelled();
        const double t = t0 + static_cast<double>(k) / sensor.rate_hz;
        const auto stamp = mrpt::Clock::fromDouble(t);
        if (k > 0) driftOdometry(o, gt[k - 1], gt[k], rng, gauss, odo, sum.distance_m);
        simulateScan(world, sensor, gt[k], stamp, rng, gauss, noise, scan, core, kinds);
        writeLabels(labels, k, t, kinds, sum);
        mrpt::obs::CObservationOdometry odom;
        odom.sensorLabel = "ODOMETRY";
        odom.timestamp = stamp;
        odom.odometry = odo;
        f.write(scan);
        f.write(odom);
        gt_traj.push_back({t, gt[k]});
        odo_traj.push_back({t, Pose2D{odo.x(), odo.y(), odo.phi()}});
        if (o.on_progress && (k + 1) % std::max<std::size_t>(1, o.progress_every) == 0)
            o.on_progress(static_cast<double>(k + 1) / gt.size(), k + 1);
    }
    f.close();  // the trailer, fsync, checked
    labels.close();
    writeTum(tmp_gt.path().string(), gt_traj, sum.ground_truth);
    writeTum(tmp_odo.path().string(), odo_traj, sum.odometry);
    throwIfCancelled();
    tmp.commit();
    tmp_gt.commit();
    tmp_odo.commit();
    tmp_labels.commit();
    sum.scans = gt.size();
    sum.duration_s = static_cast<double>(gt.size()) / sensor.rate_hz;
    if (o.on_progress) o.on_progress(1.0, sum.scans);
    return sum;
}

}  // namespace kfd
