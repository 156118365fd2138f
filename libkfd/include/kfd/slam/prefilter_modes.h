// kfd-icp-slam's pre-filter modes: each mode is a named stage list of the default registry.
#pragma once

#include <string>
#include <vector>

#include "kfd/pipeline/pipeline.h"

namespace kfd {

/// How scans are pre-filtered before scan matching.
enum class PrefilterMode {
    None,      // plain ICP-SLAM, identical to MRPT's icp-slam
    Odometry,  // drop by travelled distance/angle (motion stage), a baseline
    Keyframe,  // keyframe extraction only (distance + keyframe stages)
    Kfd,       // the full method: the [KFD] pipeline (distance, keyframe, denoise)
    Dbscan,    // the paper's comparison: DBSCAN denoise of every scan (distance + dbscan)
    Radius,    // baseline: radius outlier removal of every scan (distance + radius)
    Sor,       // baseline: statistical outlier removal of every scan (distance + sor)
    Decimate,  // baseline: keep a fixed share of the scans, evenly (decimate stage)
};

/// One mode: its name, the stages it runs (names in kfd::defaultStageRegistry()), and a
/// one-line description (for the baseline modes, the stage's registry help).
struct PrefilterModeInfo {
    PrefilterMode mode = PrefilterMode::Kfd;
    std::string name;                 // e.g. "radius"
    std::vector<std::string> stages;  // e.g. {"distance", "radius"}
    bool uses_kfd_stages = false;     // true: runs the [KFD] section's own `pipeline` list
    std::string description;
};

/// Every mode, in the order above (what a `--list-modes` flag and the experiment scripts show).
const std::vector<PrefilterModeInfo>& prefilterModes();

const char* toString(PrefilterMode m);
/// "none", "odometry", "keyframe", "kfd", "dbscan", "radius", "sor", "decimate";
/// kfd::ParameterError (field
/// "mode") otherwise.
PrefilterMode parsePrefilterMode(const std::string& s);

/// The pipeline a mode runs, built from the [KFD] parameters (every stage's parameters carry
/// over; only the stage list changes).
Pipeline::Params pipelineForMode(PrefilterMode mode, const Pipeline::Params& kfd);

}  // namespace kfd
