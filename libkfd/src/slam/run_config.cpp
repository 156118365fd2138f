#include "run_config.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "kfd/mrpt/default_stages.h"
#include "kfd/os/output_paths.h"
#include "kfd/stages/keyframe_stage.h"
#include "kfd/stages/view_keyframe_stage.h"

namespace kfd::icp_slam {
namespace {

namespace fs = std::filesystem;

void checkReadable(const std::string& role, const std::string& path) {
    if (path.empty()) return;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw SlamError(role + " not found: " + path, path);
    if (!std::ifstream(path, std::ios::binary))
        throw SlamError("cannot read the " + role + " " + path, path);
}

}  // namespace

// Options that contradict each other, before anything is read.
void checkIcpSlamOptions(const IcpSlamOptions& opts) {
    const bool matchable =
        opts.mode == PrefilterMode::Odometry || opts.mode == PrefilterMode::Decimate;
    if ((opts.odometry_target_drop_pct || opts.match_drop_of) && !matchable)
        throw SlamOptionError(
            std::string("a matched drop rate (--match-drop, --match-drop-of) applies to --mode "
                        "odometry or decimate only (not ") +
                toString(opts.mode) + ")",
            "mode");
    if (opts.odometry_target_drop_pct && opts.match_drop_of)
        throw SlamOptionError("give --match-drop or --match-drop-of, not both", "match_drop_of");
}

const std::string& checkConfigFile(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw SlamError("configuration file not found: " + path);
    return path;
}

void resolvePaths(const IcpSlamOptions& opts, const mrpt::config::CConfigFile& cfg,
                  IcpSlamSummary& sum) {
    sum.rawlog = !opts.rawlog.empty() ? opts.rawlog : cfg.read_string(kSect, "rawlog_file", "");
    sum.output_dir =
        !opts.output_dir.empty() ? opts.output_dir : cfg.read_string(kSect, "logOutput_dir", "");
    std::error_code ec;
    if (sum.rawlog.empty()) throw SlamError("no rawlog given (option or rawlog_file)");
    // A rosbag2 bag is a folder (metadata.yaml and its files): the source checks it.
    const bool folder = fs::is_directory(sum.rawlog, ec);
    if (!folder && !fs::is_regular_file(sum.rawlog, ec))
        throw SlamError("rawlog not found: " + sum.rawlog);
    if (sum.output_dir.empty()) throw SlamError("no output folder given (option or logOutput_dir)");
    if (!folder) checkReadable("rawlog", sum.rawlog);
    checkReadable("relations file", opts.relations);
    checkReadable("ground-truth trajectory", opts.ground_truth_tum);
    const std::vector<NamedPath> inputs = {{"configuration", opts.config_file},
                                           {"rawlog", sum.rawlog},
                                           {"relations file", opts.relations},
                                           {"ground-truth trajectory", opts.ground_truth_tum}};
    std::vector<NamedPath> outputs;
    for (const char* name : kIcpSlamOutputFiles)
        outputs.push_back(
            {std::string("output ") + name, (fs::path(sum.output_dir) / name).string()});
    // icp-slam's numbered files: those the output folder holds already would be replaced
    if (fs::is_directory(sum.output_dir, ec))
        for (const auto& entry : fs::directory_iterator(sum.output_dir, ec))
            if (isIcpSlamNumberedOutput(entry.path().filename().string()))
                outputs.push_back(
                    {"output " + entry.path().filename().string(), entry.path().string()});
    checkOutputPaths(inputs, outputs);
    for (const NamedPath& in : inputs)
        if (samePath(sum.output_dir, in.path))
            throw PathError(
                "the output folder " + sum.output_dir + " is the " + in.role + " " + in.path,
                sum.output_dir);
}

void applySlamGate(const mrpt::config::CConfigFile& cfg, Pipeline::Params& kfd,
                   IcpSlamSummary& sum) {
    // Both keyframe stages' guards are lowered (and those of a second instance); the summary
    // reports the first listed keyframe stage's (kfd's view_keyframe when it lists neither).
    const StageRegistry& reg = defaultStageRegistry();
    const StageChoice::Option* listed = reg.choice("selector")->listedIn(kfd.stages);
    const bool paper = listed && listed->stage == KeyframeStage::kName;
    const KeyframeGuards::Params& kf =
        paper ? static_cast<const KeyframeGuards::Params&>(kfd.get<KeyframeStage>())
              : kfd.get<ViewKeyframeStage>();
    sum.guard_translation_m_configured = kf.max_translation_m;
    sum.guard_rotation_deg_configured = kf.max_rotation_deg;
    const double gate_m = cfg.read_double(kSect, "localizationLinDistance", 0.2);
    const double gate_deg = cfg.read_double(kSect, "localizationAngDistance", 5.0);
    std::vector<KeyframeGuards::Params*> guards{&kfd.get<KeyframeStage>(),
                                                &kfd.get<ViewKeyframeStage>()};
    const std::vector<std::string> instances = instanceNames(kfd.stages);
    for (std::size_t i = 0; i < instances.size(); ++i)  // keyframe_2, view_keyframe_2, ...
        if (instances[i] != kfd.stages[i] && reg.choice("selector")->ofStage(kfd.stages[i])) {
            void* d = kfd.at(*reg.find(kfd.stages[i]), instances[i]).data();
            guards.push_back(
                kfd.stages[i] == KeyframeStage::kName
                    ? static_cast<KeyframeGuards::Params*>(static_cast<KeyframeStage::Params*>(d))
                    : static_cast<KeyframeGuards::Params*>(
                          static_cast<ViewKeyframeStage::Params*>(d)));
        }
    for (KeyframeGuards::Params* g : guards) {
        if (gate_m > 0.0 && g->max_translation_m > gate_m) g->max_translation_m = gate_m;
        if (gate_deg > 0.0 && g->max_rotation_deg > gate_deg) g->max_rotation_deg = gate_deg;
    }
    sum.guard_translation_m = kf.max_translation_m;
    sum.guard_rotation_deg = kf.max_rotation_deg;
}

void checkEvaluationOptions(const IcpSlamOptions& opts, IcpSlamSummary& sum) {
    if (!(opts.split_seconds >= 0.0) || !std::isfinite(opts.split_seconds))
        throw SlamError("the local/long split must be finite and >= 0 s (got " +
                            std::to_string(opts.split_seconds) + ")",
                        "split_seconds");
    sum.split_seconds = opts.split_seconds;
    if (!(opts.relations_max_dt >= 0.0) || !std::isfinite(opts.relations_max_dt))
        throw SlamError("the stamp matching tolerance must be finite and >= 0 (got " +
                            std::to_string(opts.relations_max_dt) + " s)",
                        "relations_max_dt");
}

}  // namespace kfd::icp_slam
