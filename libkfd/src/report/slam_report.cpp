#include "kfd/report/slam_report.h"

#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <tuple>

#include "kfd/baselines/decimate_stage.h"
#include "kfd/baselines/motion_stage.h"
#include "kfd/core/cancel.h"
#include "kfd/plot/map_figure.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;

void writeText(const fs::path& path, const std::string& text) {
    std::ofstream f(path);
    f << text;
    f.close();
    if (f.fail()) throw SlamError("cannot write " + path.string(), path.string());
}

std::string reportMarkdown(const IcpSlamSummary& sum) {
    std::string r = "# kfd-icp-slam report\n\n";
    r += "- rawlog: `" + sum.rawlog + "`\n- pre-filter mode: **" + toString(sum.mode) + "**\n";
    char line[512];
    std::snprintf(line, sizeof(line),
                  "- scans: %zu in, %zu kept (%.1f %% dropped); points removed: %zu of %zu\n"
                  "- time: pre-filter %.1f us/scan, ICP-SLAM %.3f ms/scan, CPU %.2f s\n",
                  sum.scans_in, sum.scans_kept, sum.dropped_pct, sum.points_removed, sum.points_in,
                  sum.prefilter_us_per_scan, sum.icp_ms_per_scan, sum.cpu_s_total);
    r += line;
    if (sum.scans_corridor) {
        std::snprintf(line, sizeof(line),
                      "- corridor switch: %zu scans degenerate (orange in the figure)\n",
                      sum.scans_corridor);
        r += line;
    }
    if (sum.relations) {
        std::snprintf(line, sizeof(line),
                      "- relations error (%zu used, %zu unmatched): %.4f +- %.4f m, %.3f +- "
                      "%.3f deg\n",
                      sum.relations->used, sum.relations->unmatched, sum.relations->trans_mean,
                      sum.relations->trans_std, sum.relations->rot_mean_deg,
                      sum.relations->rot_std_deg);
        r += line;
    }
    if (sum.ate_rmse) {
        std::ostringstream ate;  // as the stream prints it (6 significant digits)
        ate << *sum.ate_rmse;
        r += "- ATE RMSE after SE(2) alignment: " + ate.str() + " m\n";
    }
    r += "\n![map, estimate (blue, dots = keyframes), ground truth (green), odometry (grey)]"
         "(map_figure.png)\n\nAll numbers: `summary.json`; per scan: `scans.csv`; "
         "trajectory: `trajectory.tum`.\n";
    return r;
}

void writeMap(const IcpSlamResult& res, const fs::path& out) {
    const auto& sum = res.summary;
    {  // as CMetricMapBuilder::saveCurrentMapToFile
        mrpt::io::CFileGZOutputStream f;
        if (!f.open((out / "final_map.simplemap").string()))
            throw SlamError("cannot write " + (out / "final_map.simplemap").string());
        mrpt::serialization::archiveFrom(f) << *res.map;
    }
    mrpt::maps::COccupancyGridMap2D grid(-10, 10, -10, 10, 0.05f);
    grid.loadFromSimpleMap(*res.map);
    if (!grid.saveAsBitmapFile((out / "map.png").string()))
        throw SlamError("cannot write " + (out / "map.png").string());
    MapFigureInput fig;
    fig.grid = &grid;
    fig.estimate = res.trajectory;
    fig.ground_truth = res.ground_truth;
    fig.odometry = res.odometry;
    fig.keyframes = res.keyframes;
    fig.corridor = res.corridor;
    fig.title = fs::path(sum.rawlog).filename().string() + "  mode " + toString(sum.mode);
    if (!renderMapFigure(fig).saveToFile((out / "map_figure.png").string()))
        throw SlamError("cannot write " + (out / "map_figure.png").string());
}

// A relations error's fields (used, unmatched, means and deviations) into `o`.
void relationsJson(nlohmann::ordered_json& o, const RelationsError& r) {
    o["used"] = r.used;
    o["unmatched"] = r.unmatched;
    o["trans_mean_m"] = r.trans_mean;
    o["trans_std_m"] = r.trans_std;
    o["rot_mean_deg"] = r.rot_mean_deg;
    o["rot_std_deg"] = r.rot_std_deg;
    o["trans2_mean_m2"] = r.trans2_mean;
    o["trans2_std_m2"] = r.trans2_std;
    o["rot2_mean_deg2"] = r.rot2_mean;
    o["rot2_std_deg2"] = r.rot2_std;
}

}  // namespace

std::string toJson(const IcpSlamSummary& s) {
    nlohmann::ordered_json j;
    j["mode"] = toString(s.mode);
    j["rawlog"] = s.rawlog;
    j["stages"] = s.pipeline.stages;
    j["entries"] = s.entries;
    j["scans_in"] = s.scans_in;
    j["scans_kept"] = s.scans_kept;
    j["dropped_pct"] = s.dropped_pct;
    j["scans_corridor"] = s.scans_corridor;
    j["scans_skipped"] = s.scans_skipped;  // kfd::checkScan: bad geometry, never reached ICP
    {
        nlohmann::ordered_json by_reason = nlohmann::ordered_json::object();
        for (std::size_t r = 1; r < kScanSkipReasons; ++r)
            by_reason[toString(static_cast<ScanSkipReason>(r))] = s.skipped_by_reason[r];
        j["scans_skipped_by_reason"] = by_reason;
    }
    j["beams_bad_range"] = s.beams_bad_range;
    j["odometry_bad"] = s.odometry_bad;
    j["points_in"] = s.points_in;
    j["points_removed"] = s.points_removed;
    j["prefilter_us_per_scan"] = s.prefilter_us_per_scan;
    j["icp_ms_per_scan"] = s.icp_ms_per_scan;
    j["icp_ms_per_kept_scan"] = s.icp_ms_per_kept_scan;
    j["cpu_s_total"] = s.cpu_s_total;
    j["wall_s_total"] = s.wall_s_total;
    j["motion_distance_m"] = s.pipeline.get<MotionStage>().max_distance_m;
    j["motion_angle_deg"] = s.pipeline.get<MotionStage>().max_angle_deg;
    j["decimate_keep"] = s.pipeline.get<DecimateStage>().keep_fraction;
    if (s.target_drop_pct) j["target_drop_pct"] = *s.target_drop_pct;
    j["cpu_s_match"] = s.cpu_s_match;
    j["scans_skipped_start"] = s.scans_skipped_start;
    j["laser_only"] = s.laser_only;
    if (s.ate_rmse) j["ate_rmse_m"] = *s.ate_rmse;
    if (s.relations) {
        const auto& r = *s.relations;
        nlohmann::ordered_json rel;
        rel["file"] = s.relations_file;
        relationsJson(rel, r);
        j["relations"] = std::move(rel);
        j["split_seconds"] = s.split_seconds;
        for (const auto& [key, sub, n] :
             {std::tuple{"relations_local", &s.relations_local, s.relations_local_count},
              std::tuple{"relations_long", &s.relations_long, s.relations_long_count}}) {
            nlohmann::ordered_json o;
            o["count"] = n;
            if (*sub) relationsJson(o, **sub);
            j[key] = std::move(o);
        }
    }
    return j.dump(2) + "\n";
}

void writeIcpSlamReport(const IcpSlamResult& result) {
    if (!result.output) throw SlamError("no staged output folder in the result");
    if (result.output->committed()) throw SlamError("the output was already committed");
    const fs::path out = result.output->path();
    if (result.map) writeMap(result, out);
    throwIfCancelled();
    writeText(out / "summary.json", toJson(result.summary));
    if (result.map) writeText(out / "report.md", reportMarkdown(result.summary));
    throwIfCancelled();
    result.output->commit();
}

}  // namespace kfd
