// kfd-simulate's logic: rawlogs of a robot driving through a World, with ground truth and labels.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "kfd/sim/noise_injector.h"
#include "kfd/sim/world.h"

namespace kfd {

/// A laser model.
struct SensorModel {
    double rate_hz = 40.0;
    std::size_t beams = 1081;
    double fov_deg = 270.0;
    double min_range = 0.1, max_range = 30.0;  // m
    double range_sigma = 0.01;                 // m, Gaussian range noise of true returns
};
/// "mit": the paper's MIT sensor class (40 Hz, 1081 beams over 270 deg, 0.1-30 m).
/// "gazebo": the paper's Gazebo sensor (Sec. 4.2: 10 Hz, 720 beams at 0.5 deg, 0.1-12 m).
SensorModel sensorModel(const std::string& name);

struct SimulationOptions {
    std::string world = "office";  // built-in world, or...
    std::string gridmap, route;    // ... an MRPT gridmap and a route file
    std::string sensor = "mit";
    double speed_mps = 0.752;     // the paper's two bag groups: 0.752 and 0.575
    double turn_rate_dps = 45.0;  // deg/s when turning in place
    double duration_s = 0.0;      // 0 = the whole route once; otherwise stop after this
    NoiseInjector::Params noise;
    // Odometry error model: per-step Gaussian noise proportional to the motion, plus a
    // systematic heading drift per metre (what makes odometry alone drift over a run).
    double odo_trans_sigma = 0.02;     // fraction of the step length
    double odo_rot_sigma = 0.01;       // rad per rad turned
    double odo_drift_deg_per_m = 0.5;  // deg of heading bias per metre travelled
    std::uint32_t seed = 1;
    std::string output;  // OUT.rawlog; writes OUT.gt.tum, OUT.odom.tum, OUT.labels.csv beside it
    /// Called every progress_every scans and at the end: the fraction of the route done and the
    /// scans written so far.
    std::function<void(double fraction, std::size_t scans)> on_progress;
    std::size_t progress_every = 200;
};

struct SimulationSummary {
    std::size_t scans = 0;
    double duration_s = 0, distance_m = 0;
    std::size_t noise_isolated = 0, noise_clustered = 0, noise_edge = 0;
    std::string rawlog, ground_truth, odometry, labels;
};

/// Simulates the route at the sensor rate: ground-truth poses, ray-cast scans
/// (COccupancyGridMap2D::laserScanSimulator), labelled outliers (NoiseInjector), and drifting
/// odometry. Writes an observations-only rawlog (one CObservation2DRangeScan "LASER" and one
/// CObservationOdometry per scan), the ground truth and the odometry as TUM, and a label CSV
/// ("scan,timestamp,beam,kind" for every outlier beam; all other beams are clean). The same
/// options and seed give byte-identical files. The four outputs are written under temporary
/// names through kfd's checked writers and renamed when all four are complete and checked: a
/// WriteError ("cannot write sim.rawlog: No space left on device") leaves none of them.
class Simulator {
  public:
    SimulationSummary run(const SimulationOptions& opts);
};

}  // namespace kfd
