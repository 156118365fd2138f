#include "kfd/slam/icp_slam_logs.h"

#include <mrpt/maps/CMultiMetricMap.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/maps/CPointsMap.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPlanarLaserScan.h>
#include <mrpt/opengl/stock_objects.h>
#include <mrpt/poses/CPose3DPDFGaussian.h>
#include <mrpt/system/filesystem.h>
#include <mrpt/system/memory.h>
#include <mrpt/system/string_utils.h>

#include <cctype>
#include <string>

#include "kfd/io/gz_output.h"
#include "kfd/io/png_output.h"
#include "kfd/io/source.h"
#include "kfd/mrpt/config.h"
#include "kfd/pipeline/format.h"

namespace kfd {
namespace {

using mrpt::poses::CPose2D;
using mrpt::poses::CPose3D;

bool finite(const CPose2D& p) { return finitePose(p.x(), p.y(), p.phi()); }

// The map builder's frame in the log's (a translation).
CPose3D placeOf(const Pose2D& map_origin) {
    return CPose3D(map_origin.x, map_origin.y, 0.0, 0.0, 0.0, 0.0);
}

// MRPT's read_int reads "1.5" as 1 and read_bool "abc" as false, silently: these read the
// whole value or refuse it, naming the key.
int strictInt(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
              const std::string& key, int fallback) {
    const std::string t = mrpt::system::trim(cfg.read_string(section, key, ""));
    if (t.empty()) return fallback;
    const std::size_t digits = t[0] == '-' || t[0] == '+' ? 1 : 0;
    if (t.size() == digits || t.size() > digits + 9 ||
        t.find_first_not_of("0123456789", digits) != std::string::npos)
        throw ConfigError(key, "'" + t + "' in [" + section + "] is not an integer");
    return std::stoi(t);
}

bool strictBool(const mrpt::config::CConfigFileBase& cfg, const std::string& section,
                const std::string& key, bool fallback) {
    std::string t = mrpt::system::trim(cfg.read_string(section, key, ""));
    if (t.empty()) return fallback;
    for (auto& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (t == "true" || t == "yes" || t == "on" || t == "1") return true;
    if (t == "false" || t == "no" || t == "off" || t == "0") return false;
    throw ConfigError(key, "'" + t + "' in [" + section + "] is not true or false");
}

}  // namespace

IcpSlamLogParams IcpSlamLogParams::fromConfig(const mrpt::config::CConfigFileBase& cfg,
                                              const std::string& section,
                                              std::vector<std::string>& notices) {
    IcpSlamLogParams p;
    p.log_frequency = strictInt(cfg, section, "LOG_FREQUENCY", p.log_frequency);
    p.save_pose_log = strictBool(cfg, section, "SAVE_POSE_LOG", p.save_pose_log);
    p.save_3d_scene = strictBool(cfg, section, "SAVE_3D_SCENE", p.save_3d_scene);
    p.camera_follows_robot =
        strictBool(cfg, section, "CAMERA_3DSCENE_FOLLOWS_ROBOT", p.camera_follows_robot);
    p.show_laser_scans = strictBool(cfg, section, "SHOW_LASER_SCANS_3D", p.show_laser_scans);
    const std::string key = "[" + section + "] ";
    if (strictBool(cfg, section, "SHOW_PROGRESS_3D_REAL_TIME", false))
        notices.push_back(key +
                          "SHOW_PROGRESS_3D_REAL_TIME = true ignored: kfd-icp-slam has no window "
                          "(SAVE_3D_SCENE writes the same scenes, for SceneViewer3D)");
    if (cfg.keyExists(section, "verbosity"))
        notices.push_back(key +
                          "verbosity ignored: kfd-icp-slam prints its own summary, not MRPT's "
                          "per-step log");
    if (p.log_frequency <= 0)
        for (const auto& [name, on] : {std::pair{"SAVE_POSE_LOG", p.save_pose_log},
                                       std::pair{"SAVE_3D_SCENE", p.save_3d_scene}})
            if (on)
                notices.push_back(key + name + " = true writes nothing: LOG_FREQUENCY = " +
                                  std::to_string(p.log_frequency) + " (it needs > 0)");
    return p;
}

IcpSlamLogs::IcpSlamLogs(const StagedOutputFolder& out, const IcpSlamLogParams& params)
    : out_(out),
      params_(params),
      path_(out.path() / "log_estimated_path.txt", out.finalName("log_estimated_path.txt")),
      odometry_(out.path() / "log_odometry_path.txt", out.finalName("log_odometry_path.txt")),
      times_(out.path() / "log_times.txt", out.finalName("log_times.txt")),
      memory_(out.path() / "log_MemoryUsage.txt", out.finalName("log_MemoryUsage.txt")) {}

void IcpSlamLogs::beginStep(const mrpt::obs::CObservation::Ptr& observation,
                            const mrpt::obs::CActionCollection* action,
                            const mrpt::obs::CSensoryFrame* frame) {
    using mrpt::obs::CObservation2DRangeScan;
    scans_.clear();
    const bool draw = params_.save_3d_scene && params_.show_laser_scans;
    if (observation) {
        if (const auto* odo =
                dynamic_cast<const mrpt::obs::CObservationOdometry*>(observation.get())) {
            const CPose2D reading(odo->odometry);
            if (finite(reading)) {  // the change since the last reading (none for the first)
                if (last_reading_) odometry_pose_ = odometry_pose_ + (reading - *last_reading_);
                last_reading_ = reading;
            }
        } else if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(observation);
                   scan && draw) {
            scans_.push_back(std::move(scan));
        }
        return;
    }
    if (action)
        if (auto mv = action->getBestMovementEstimation(); mv && mv->poseChange)
            if (const CPose2D d = mv->poseChange->getMeanVal(); finite(d))
                odometry_pose_ = odometry_pose_ + d;
    if (draw && frame)
        for (const auto& o : *frame)
            if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o))
                scans_.push_back(std::move(scan));
}

void IcpSlamLogs::endStep(std::size_t step, const mrpt::slam::CMetricMapBuilderICP& builder,
                          double builder_ms, const CPose3D& pose, const Pose2D& map_origin) {
    const int n = static_cast<int>(step);
    path_ << format("%i %f %f %f\n", n, pose.x(), pose.y(), pose.yaw());
    odometry_ << format("%i %f %f %f\n", n, odometry_pose_.x(), odometry_pose_.y(),
                        odometry_pose_.phi());
    // getCurrentlyBuiltMapSize() is not const in MRPT; it only reads the map's frame count.
    times_ << format(
        "%f %i\n", builder_ms,
        static_cast<int>(
            const_cast<mrpt::slam::CMetricMapBuilderICP&>(builder).getCurrentlyBuiltMapSize()));
    memory_ << format("%u\t%lu\n", static_cast<unsigned>(step), mrpt::system::getMemoryUsage());
    if (params_.log_frequency > 0 && step % static_cast<std::size_t>(params_.log_frequency) == 0) {
        if (params_.save_pose_log) writePosePdf(step, builder, map_origin);
        if (params_.save_3d_scene) write3DScene(step, builder, pose, map_origin);
    }
    scans_.clear();
}

// As CPose3DPDFGaussian::saveToTextFile: the mean (x y z yaw pitch roll), then the covariance.
void IcpSlamLogs::writePosePdf(std::size_t step, const mrpt::slam::CMetricMapBuilderICP& builder,
                               const Pose2D& map_origin) {
    mrpt::poses::CPose3DPDFGaussian pdf;
    pdf.copyFrom(*builder.getCurrentPoseEstimation());
    if (map_origin.x != 0.0 || map_origin.y != 0.0) pdf.mean = placeOf(map_origin) + pdf.mean;
    const auto& m = pdf.mean;
    std::string text =
        format("%e %e %e %e %e %e\n", m.x(), m.y(), m.z(), m.yaw(), m.pitch(), m.roll());
    for (int i = 0; i < 6; ++i)
        text += format("%e %e %e %e %e %e\n", pdf.cov(i, 0), pdf.cov(i, 1), pdf.cov(i, 2),
                       pdf.cov(i, 3), pdf.cov(i, 4), pdf.cov(i, 5));
    const std::string name = format("mapbuild_posepdf_%03u.txt", static_cast<unsigned>(step));
    OutputFile f(out_.path() / name, out_.finalName(name));
    f << text;
    f.close();
}

// The scene icp-slam saves: in the main viewport the ground, the map, the robot and the step's
// scans; a top-view "mini-map" with the point map and the robot. In the log's frame.
void IcpSlamLogs::write3DScene(std::size_t step, const mrpt::slam::CMetricMapBuilderICP& builder,
                               const CPose3D& pose, const Pose2D& map_origin) {
    using namespace mrpt::opengl;
    // The builder's objects moved into the log's frame (untouched in the usual case: the
    // scene then holds icp-slam's bytes).
    const bool moved = map_origin.x != 0.0 || map_origin.y != 0.0;
    const auto place = [&](const CRenderizable::Ptr& obj) {
        if (moved) obj->setPose(placeOf(map_origin));
    };
    const mrpt::maps::CMultiMetricMap* map = builder.getCurrentlyBuiltMetricMap();
    auto scene = COpenGLScene::Create();
    COpenGLViewport::Ptr view = scene->getViewport("main");
    COpenGLViewport::Ptr mini = scene->createViewport("mini-map");
    mini->setBorderSize(2);
    mini->setViewportPosition(0.01, 0.01, 0.35, 0.35);
    mini->setTransparent(false);
    CCamera& cam = mini->getCamera();
    cam.setAzimuthDegrees(-90);
    cam.setElevationDegrees(90);
    cam.setPointingAt(pose);
    cam.setZoomDistance(20);  // perspective: what MRPT 2.5's icp-slam writes
    auto ground = CGridPlaneXY::Create(-200, 200, -200, 200, 0, 5);
    ground->setColor(0.4, 0.4, 0.4);
    place(ground);
    view->insert(ground);
    mini->insert(ground);
    if (params_.camera_follows_robot) {
        scene->enableFollowCamera(true);
        cam.setAzimuthDegrees(-45);
        cam.setElevationDegrees(45);
    }
    auto built = map->getVisualization();
    place(built);
    view->insert(built);
    if (auto points = map->mapByClass<mrpt::maps::CPointsMap>()) {
        auto obj = points->getVisualization();
        place(obj);
        mini->insert(obj);
    }
    for (const auto& v : {view, mini}) {
        auto robot = stock_objects::RobotPioneer();
        robot->setPose(pose);
        v->insert(robot);
    }
    for (const auto& scan : scans_) {
        auto obj = CPlanarLaserScan::Create();
        obj->setScan(*scan);
        obj->setPose(pose);
        obj->setSurfaceColor(1.0f, 0.0f, 0.0f, 0.5f);
        view->insert(obj);
    }
    const std::string name = format("buildingmap_%05u.3Dscene", static_cast<unsigned>(step));
    GzOutputStream f(out_.path() / name, out_.finalName(name), 1);
    f.write(*scene);
    f.close();
}

void IcpSlamLogs::finish(const mrpt::slam::CMetricMapBuilderICP& builder, const Pose2D& map_origin,
                         bool with_map, std::vector<std::string>& notices) {
    if (with_map) {
        mrpt::maps::CSimpleMap map;
        builder.getCurrentlyBuiltMap(map);
        writeSimpleMap(map, map_origin, out_.path() / "_finalmap_.simplemap",
                       out_.finalName("_finalmap_.simplemap"));
        writeFinalMaps(builder, map_origin, notices);
    }
    for (OutputFile* f : {&path_, &odometry_, &times_, &memory_}) f->close();
}

// As CMultiMetricMap::saveMetricMapRepresentationToFile("_finalmaps_.txt"): one name per map,
// "_finalmaps_.txt_" + its class name (':' made '_') + "_NN", as each map kind writes it.
void IcpSlamLogs::writeFinalMaps(const mrpt::slam::CMetricMapBuilderICP& builder,
                                 const Pose2D& map_origin, std::vector<std::string>& notices) {
    const auto& maps = builder.getCurrentlyBuiltMetricMap()->maps;
    for (std::size_t idx = 0; idx < maps.size(); ++idx) {
        const mrpt::maps::CMetricMap* m = maps[idx].get();
        const std::string cls = m->GetRuntimeClass()->className;
        const std::string prefix =
            format("_finalmaps_.txt_%s_%02u", mrpt::system::fileNameStripInvalidChars(cls).c_str(),
                   static_cast<unsigned>(idx));
        if (const auto* points = dynamic_cast<const mrpt::maps::CPointsMap*>(m)) {
            // CPointsMap: save3D_to_text_file, "x y z" per point
            OutputFile f(out_.path() / (prefix + ".txt"), out_.finalName(prefix + ".txt"));
            float x, y, z;
            for (std::size_t i = 0; i < points->size(); ++i) {
                points->getPoint(i, x, y, z);
                f << format("%f %f %f\n", x + map_origin.x, y + map_origin.y, z);
            }
            f.close();
        } else if (const auto* grid = dynamic_cast<const mrpt::maps::COccupancyGridMap2D*>(m)) {
            // COccupancyGridMap2D: saveAsBitmapFile and the grid's limits
            mrpt::img::CImage img;
            grid->getAsImage(img);
            writePng(img, out_.path() / (prefix + ".png"), out_.finalName(prefix + ".png"));
            const std::string limits = prefix + "_limits.txt";
            OutputFile f(out_.path() / limits, out_.finalName(limits));
            f << "% Grid limits: [x_min x_max y_min y_max]\n"
              << format("%.16f %.16f %.16f %.16f\n", grid->getXMin() + map_origin.x,
                        grid->getXMax() + map_origin.x, grid->getYMin() + map_origin.y,
                        grid->getYMax() + map_origin.y);
            f.close();
        } else {
            notices.push_back("map " + std::to_string(idx) + " (" + cls +
                              ") not saved as _finalmaps_.txt_*: kfd-icp-slam writes point maps "
                              "and occupancy grids (it is in _finalmap_.simplemap's scans)");
        }
    }
}

void writeSimpleMap(const mrpt::maps::CSimpleMap& map, const Pose2D& map_origin,
                    const std::filesystem::path& path, const std::string& name) {
    const mrpt::maps::CSimpleMap* out = &map;
    mrpt::maps::CSimpleMap moved;
    if (map_origin.x != 0.0 || map_origin.y != 0.0) {
        moved = map;  // poses copied, observations shared
        moved.changeCoordinatesOrigin(placeOf(map_origin));
        out = &moved;
    }
    GzOutputStream f(path, name, 1);
    f.write(*out);
    f.close();
}

}  // namespace kfd
