// MRPT's icp-slam output files (ICP_SLAM_App, MRPT 2.5), written by kfd-icp-slam so that a user
// switching from icp-slam finds the files they had: the per-step logs, the periodic pose PDFs
// and 3D scenes of [MappingApplication]'s LOG_FREQUENCY, SAVE_POSE_LOG and SAVE_3D_SCENE, and
// the final maps.
#pragma once

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservation.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/slam/CMetricMapBuilderICP.h>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "kfd/os/output_paths.h"
#include "kfd/pipeline/scan.h"

namespace kfd {

/// icp-slam's output keys in [MappingApplication], with icp-slam's defaults.
struct IcpSlamLogParams {
    int log_frequency = 5;       // LOG_FREQUENCY: the periodic files every N steps (<= 0: none)
    bool save_pose_log = false;  // SAVE_POSE_LOG: mapbuild_posepdf_NNN.txt
    bool save_3d_scene = false;  // SAVE_3D_SCENE: buildingmap_NNNNN.3Dscene
    bool camera_follows_robot = true;  // CAMERA_3DSCENE_FOLLOWS_ROBOT (the scenes' camera)
    bool show_laser_scans = true;      // SHOW_LASER_SCANS_3D: the step's scans in the scenes

    /// The keys of `section`. What kfd-icp-slam cannot honour adds a notice naming the key to
    /// `notices` (the caller shows them; nothing is refused): SHOW_PROGRESS_3D_REAL_TIME = true
    /// (a live window: kfd has no GUI), `verbosity` (MRPT's console log), and SAVE_POSE_LOG or
    /// SAVE_3D_SCENE with LOG_FREQUENCY <= 0 (no periodic file).
    static IcpSlamLogParams fromConfig(const mrpt::config::CConfigFileBase& cfg,
                                       const std::string& section,
                                       std::vector<std::string>& notices);
};

/// The files of one run as icp-slam names and formats them, written into a staged output folder
/// through kfd's checked writers (OutputFile, GzOutputStream, writePng): a failed write is a
/// WriteError naming the file's final name and the reason. One step is one of icp-slam's
/// steps (log_estimated_path.txt's numbering, from 0). Every step:
///  - log_estimated_path.txt "step x y phi" (the map builder's pose, the log's frame);
///  - log_odometry_path.txt "step x y phi": the log's odometry, accumulated from (0, 0, 0) as
///    icp-slam does (action logs: the actions' movement; observation logs: the change between
///    odometry readings); a non-finite reading changes nothing;
///  - log_times.txt "ms size": the map builder's time for the step (re-matches included) and
///    the number of frames in its map;
///  - log_MemoryUsage.txt "step<TAB>bytes" (the process's memory use).
/// Every LOG_FREQUENCY-th step: mapbuild_posepdf_NNN.txt (SAVE_POSE_LOG: the pose PDF, mean
/// x y z yaw pitch roll then the 6x6 covariance, "%e") and buildingmap_NNNNN.3Dscene
/// (SAVE_3D_SCENE: a gzip'ed mrpt::opengl::COpenGLScene, for SceneViewer3D: the ground, the
/// map, the robot, the step's scans and a top-view mini-map, as icp-slam draws it).
/// At the end (finish(), with the map): _finalmap_.simplemap and, per map of the builder,
/// _finalmaps_.txt_CLASS_NN.txt (a point map: "x y z" per point) or .png and _limits.txt (an
/// occupancy grid: the image and its x_min x_max y_min y_max).
class IcpSlamLogs {
  public:
    IcpSlamLogs(const StagedOutputFolder& out, const IcpSlamLogParams& params);

    /// Before the step reaches the map builder: its odometry (the log's: `action`, or an
    /// odometry `observation`) and its scans (for the 3D scene).
    void beginStep(const mrpt::obs::CObservation::Ptr& observation,
                   const mrpt::obs::CActionCollection* action,
                   const mrpt::obs::CSensoryFrame* frame);
    /// After it: the step's lines and periodic files. `pose` in the log's frame; `map_origin`
    /// the builder's frame in the log's (IcpSlamResult::map_origin).
    void endStep(std::size_t step, const mrpt::slam::CMetricMapBuilderICP& builder,
                 double builder_ms, const mrpt::poses::CPose3D& pose, const Pose2D& map_origin);
    /// The final maps (when `with_map`) and every file closed, checked. A map kind kfd cannot
    /// write adds a notice naming it.
    void finish(const mrpt::slam::CMetricMapBuilderICP& builder, const Pose2D& map_origin,
                bool with_map, std::vector<std::string>& notices);

  private:
    void writePosePdf(std::size_t step, const mrpt::slam::CMetricMapBuilderICP& builder,
                      const Pose2D& map_origin);
    void write3DScene(std::size_t step, const mrpt::slam::CMetricMapBuilderICP& builder,
                      const mrpt::poses::CPose3D& pose, const Pose2D& map_origin);
    void writeFinalMaps(const mrpt::slam::CMetricMapBuilderICP& builder, const Pose2D& map_origin,
                        std::vector<std::string>& notices);

    const StagedOutputFolder& out_;
    IcpSlamLogParams params_;
    OutputFile path_, odometry_, times_, memory_;
    mrpt::poses::CPose2D odometry_pose_;                // accumulated from (0, 0, 0)
    std::optional<mrpt::poses::CPose2D> last_reading_;  // an observation log's last odometry
    std::vector<mrpt::obs::CObservation2DRangeScan::Ptr> scans_;  // the step's
};

/// `map` (in the map builder's frame) written as a .simplemap (gzip level 1, as
/// CMetricMapBuilder::saveCurrentMapToFile) in the log's frame: moved by `map_origin`.
void writeSimpleMap(const mrpt::maps::CSimpleMap& map, const Pose2D& map_origin,
                    const std::filesystem::path& path, const std::string& name);

}  // namespace kfd
