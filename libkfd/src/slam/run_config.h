// kfd-icp-slam's configuration before a run: options that contradict each other, the paths
// (every input readable, no output aliasing one), the SLAM's localisation gate applied to kfd's
// keyframe guards (an explicit step the summary reports), the evaluation options. Internal to
// kfd_slam.
#pragma once

#include <mrpt/config/CConfigFile.h>

#include <string>

#include "kfd/pipeline/pipeline.h"
#include "kfd/slam/icp_slam_runner.h"

namespace kfd::icp_slam {

/// The section of icp-slam's configuration that kfd-icp-slam reads.
inline constexpr const char* kSect = "MappingApplication";

/// Options that contradict each other, before anything is read: SlamOptionError.
void checkIcpSlamOptions(const IcpSlamOptions& opts);

/// The configuration file's path, checked: SlamError when it is not a file.
const std::string& checkConfigFile(const std::string& path);

/// The log and the output folder (options, else the configuration's rawlog_file and
/// logOutput_dir) into sum; every input readable and no output on an input (SlamError,
/// PathError); icp-slam's numbered files already in the folder count as outputs.
void resolvePaths(const IcpSlamOptions& opts, const mrpt::config::CConfigFile& cfg,
                  IcpSlamSummary& sum);

/// The SLAM's localisation gate: ICP corrects the pose only after localizationLinDistance (m)
/// or localizationAngDistance (deg) of odometry since its last correction. kfd's keyframe
/// guards (those that are on) are lowered to it, so that a drop never skips the scan the gate
/// would have matched. The summary reports both: the guards configured and those used.
void applySlamGate(const mrpt::config::CConfigFile& cfg, Pipeline::Params& kfd,
                   IcpSlamSummary& sum);

/// The local/long split and the stamp tolerance: finite and >= 0 (SlamError), into sum.
void checkEvaluationOptions(const IcpSlamOptions& opts, IcpSlamSummary& sum);

}  // namespace kfd::icp_slam
