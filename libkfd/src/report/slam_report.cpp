#include "kfd/report/slam_report.h"

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/poses/CPose3D.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <tuple>
#include <utility>
#include <vector>

#include "kfd/baselines/decimate_stage.h"
#include "kfd/baselines/motion_stage.h"
#include "kfd/io/gz_output.h"
#include "kfd/io/png_output.h"
#include "kfd/mrpt/default_stages.h"
#include "kfd/mrpt/stream_filter.h"
#include "kfd/os/cancel.h"
#include "kfd/os/output_paths.h"
#include "kfd/pipeline/format.h"
#include "kfd/plot/map_figure.h"

namespace kfd {
namespace {

namespace fs = std::filesystem;

// Every file of the folder through kfd's checked writers (OutputFile, GzOutputStream,
// writePng): a failure is a WriteError naming the file's final name and the reason.
void writeText(const StagedOutputFolder& out, const std::string& name, const std::string& text) {
    OutputFile f(out.path() / name, out.finalName(name));
    f << text;
    f.close();
}

}  // namespace

namespace {

// The log's scans that are not in scans_in (kfd-filter counts them in its "in"), or "".
std::string scansNotIn(const IcpSlamSummary& s) {
    std::string not_in;
    auto add = [&](std::size_t n, const char* why) {
        if (n) not_in += (not_in.empty() ? "" : ", ") + plural(n, "scan") + " " + why;
    };
    add(s.scans_without_step,
        "in a sensory frame without an odometry action (MRPT's icp-slam reads no step from it)");
    add(s.scans_before_offset, "before rawlog_offset");
    add(s.scans_skipped_start, "skipped at the start (--skip-scans)");
    return not_in;
}

}  // namespace

std::string reportMarkdown(const IcpSlamSummary& sum,
                           const std::vector<MapFigureLayer>& figure_layers) {
    std::string r = "# kfd-icp-slam report\n\n";
    r += "- rawlog: `" + sum.rawlog + "`\n- pre-filter mode: **" + toString(sum.mode) + "**\n";
    r += format(
        "- scans: %zu in, %zu kept (%.1f %% dropped); points removed: %zu of %zu\n"
        "- time: pre-filter %.1f us/scan, ICP-SLAM %.3f ms/scan, CPU %.2f s, wall %.2f s\n",
        sum.scans_in, sum.scans_kept, sum.dropped_pct, sum.points_removed, sum.points_in,
        sum.prefilter_us_per_scan, sum.icp_ms_per_scan, sum.cpu_s_total, sum.wall_s_total);
    if (const std::string n = scansNotIn(sum); !n.empty()) r += "- not in: " + n + "\n";
    if (sum.icp_runs)
        r += format("- ICP: %s, %zu rejected (goodness below the minimum), median goodness %.2f\n",
                    plural(sum.icp_runs, "correction").c_str(), sum.icp_rejected,
                    sum.icp_goodness_median);
    if (sum.rematches)
        r += format(
            "- re-matches after a rejected correction: %zu (%zu of them after kfd's gap check; "
            "ICP then accepted the rejected scan in %zu), %s matched again\n",
            sum.rematches, sum.gap_checks_failed, sum.rematches_recovered,
            plural(sum.scans_rematched, "dropped scan").c_str());
    if (!sum.lost_track_stamps.empty()) {
        r += format(
            "- **%s** (%zu ICP corrections rejected in a row: the "
            "pose then follows odometry alone and the map is not updated), from t =",
            plural(sum.lost_track_stamps.size(), "suspected lost track").c_str(),
            kLostTrackRejections);
        for (std::size_t i = 0; i < sum.lost_track_stamps.size() && i < 10; ++i)
            r += format("%s %.3f", i ? "," : "", sum.lost_track_stamps[i]);
        r += sum.lost_track_stamps.size() > 10 ? ", ... s\n" : " s\n";
    }
    for (const std::string& line : stageCounterLines(sum.stage_totals)) r += "- " + line + "\n";
    if (sum.ate_rmse) r += format("- ATE RMSE after SE(2) alignment: %.4f m\n", *sum.ate_rmse);
    if (sum.relations) {
        const auto& a = *sum.relations;
        r += format(
            "- relations error (%zu used, %zu unmatched): %.4f +- %.4f m, %.3f +- %.3f deg\n",
            a.used, a.unmatched, a.trans_mean, a.trans_std, a.rot_mean_deg, a.rot_std_deg);
        for (const auto& [name, sub, n] :
             {std::tuple{"local", &sum.relations_local, sum.relations_local_count},
              std::tuple{"long", &sum.relations_long, sum.relations_long_count}}) {
            r += format("  - %s (%s %g s apart, %zu relations): ", name,
                        sub == &sum.relations_local ? "<=" : ">", sum.split_seconds, n);
            if (*sub)
                r += format("%zu used, %zu unmatched: %.4f +- %.4f m, %.3f +- %.3f deg\n",
                            (*sub)->used, (*sub)->unmatched, (*sub)->trans_mean, (*sub)->trans_std,
                            (*sub)->rot_mean_deg, (*sub)->rot_std_deg);
            else
                r += n ? "none matched a pose\n" : "none\n";
        }
    }
    if (sum.target_drop_pct) r += format("- matched drop target: %.2f %%\n", *sum.target_drop_pct);
    const std::string caption = mapFigureCaption(figure_layers);
    r += "\n![" + caption + "](map_figure.png)\n\n*" + caption +
         "*\n\nAll numbers: `summary.json`; per scan: `scans.csv`; trajectory: `trajectory.tum`.\n";
    return r;
}

namespace {

// The map image and figure are drawn in a local frame whose origin is the estimate's first
// position (rounded to the metre), on a grid whose cell size keeps it within kMaxMapCells:
// odometry and poses anywhere a double holds them (UTM coordinates, a track lost far away) give
// a bounded image, never an allocation beyond the budget.
constexpr double kMaxMapCells = 36.0e6;  // e.g. 6000 x 6000 cells (the RGB figure ~ 108 MB)
constexpr double kMapResolution = 0.05;  // m per cell, the default (icp-slam's)

struct MapFrame {
    mrpt::poses::CPose3D origin;  // the local frame in map coordinates (a translation)
    double resolution = kMapResolution;
};

MapFrame mapFrame(const IcpSlamResult& res, double insertion_reach) {
    MapFrame f;
    double x0 = 0.0, y0 = 0.0, xmin = 0.0, xmax = 0.0, ymin = 0.0, ymax = 0.0;
    bool first = true;
    for (const auto& p : res.trajectory) {
        if (!std::isfinite(p.pose.x) || !std::isfinite(p.pose.y)) continue;
        if (first) {
            x0 = std::round(p.pose.x), y0 = std::round(p.pose.y);
            first = false;
        }
        const double x = p.pose.x - x0, y = p.pose.y - y0;
        xmin = std::min(xmin, x), xmax = std::max(xmax, x);
        ymin = std::min(ymin, y), ymax = std::max(ymax, y);
    }
    // The grid takes the scans' points up to insertion_reach from their pose (its
    // maxDistanceInsertion), and grows only that far around the poses.
    const double reach = insertion_reach;
    const double w = xmax - xmin + 2.0 * reach + 20.0, h = ymax - ymin + 2.0 * reach + 20.0;
    f.resolution = std::max(kMapResolution, std::sqrt(w * h / kMaxMapCells));
    f.origin = mrpt::poses::CPose3D(x0, y0, 0.0, 0.0, 0.0, 0.0);
    return f;
}

Trajectory inFrame(const Trajectory& t, const MapFrame& f) {
    Trajectory out = t;
    for (auto& p : out) p.pose.x -= f.origin.x(), p.pose.y -= f.origin.y();
    return out;
}

}  // namespace

std::string mapTitle(const IcpSlamSummary& sum) {
    std::string t = fs::path(sum.rawlog).filename().string() + "  mode " + toString(sum.mode) +
                    format("  dropped %.1f %%", sum.dropped_pct);
    if (sum.ate_rmse) t += format("  ATE %.3f m", *sum.ate_rmse);
    t += sum.lost_track_stamps.empty()
             ? std::string("  no lost track")
             : "  " + plural(sum.lost_track_stamps.size(), "suspected lost track");
    return t;
}

namespace {

// Writes final_map.simplemap, map.png and map_figure.png; returns the figure's layers.
std::vector<MapFigureLayer> writeMap(const IcpSlamResult& res, const StagedOutputFolder& out) {
    const auto& sum = res.summary;
    // in the log's frame (like trajectory.tum); the map as built is in the builder's frame
    writeSimpleMap(*res.map, res.map_origin, out.path() / "final_map.simplemap",
                   out.finalName("final_map.simplemap"));
    mrpt::maps::COccupancyGridMap2D grid(-10, 10, -10, 10, static_cast<float>(kMapResolution));
    const MapFrame frame = mapFrame(res, grid.insertionOptions.maxDistanceInsertion);
    mrpt::maps::CSimpleMap local = *res.map;  // poses copied, observations shared
    const double dx = res.map_origin.x - frame.origin.x(), dy = res.map_origin.y - frame.origin.y();
    if (dx != 0.0 || dy != 0.0)
        local.changeCoordinatesOrigin(mrpt::poses::CPose3D(dx, dy, 0.0, 0.0, 0.0, 0.0));
    grid.setSize(-10, 10, -10, 10, static_cast<float>(frame.resolution));
    grid.loadFromSimpleMap(local);
    {  // as COccupancyGridMap2D::saveAsBitmapFile (+y up), the known cells and 1 m around them
        mrpt::img::CImage img;
        grid.getAsImage(img);
        if (const auto box = knownCellBox(grid)) {
            const int m = static_cast<int>(std::ceil(1.0 / grid.getResolution()));
            const int nx = static_cast<int>(grid.getSizeX()),
                      ny = static_cast<int>(grid.getSizeY());
            const int x0 = std::max(0, box->x0 - m), x1 = std::min(nx - 1, box->x1 + m);
            const int y0 = std::max(0, box->y0 - m), y1 = std::min(ny - 1, box->y1 + m);
            mrpt::img::CImage part;
            img.extract_patch(part, x0, ny - 1 - y1, x1 - x0 + 1, y1 - y0 + 1);
            img = std::move(part);
        }
        writePng(img, out.path() / "map.png", out.finalName("map.png"));
    }
    MapFigureInput fig;
    fig.grid = &grid;
    fig.estimate = inFrame(res.trajectory, frame);
    fig.ground_truth = res.ground_truth;  // aligned to the estimate by the figure
    if (!sum.laser_only)                  // a laser-only run never saw it: not drawn, not named
        fig.odometry = res.odometry;      // put on the estimate's start by the figure
    fig.track = res.track;                // put on the estimate's start by the figure
    fig.keyframes = res.keyframes;
    fig.corridor = res.corridor;
    for (const double t : sum.lost_track_stamps)
        if (const auto k = nearest(fig.estimate, t, 1.0)) fig.lost_tracks.push_back(*k);
    fig.title = mapTitle(sum);
    if (frame.origin.x() != 0.0 || frame.origin.y() != 0.0)
        fig.title += format("  (origin at x %.0f, y %.0f m)", frame.origin.x(), frame.origin.y());
    const MapFigure drawn = renderMapFigure(fig);
    writePng(drawn.image, out.path() / "map_figure.png", out.finalName("map_figure.png"));
    return drawn.layers;
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

namespace {

using Json = nlohmann::ordered_json;

// The scans and points: what went in, what the pre-filter kept, skipped and removed.
void scansJson(Json& j, const IcpSlamSummary& s) {
    j["mode"] = toString(s.mode);
    j["rawlog"] = s.rawlog;
    j["stages"] = s.pipeline.stages;
    j["entries"] = s.entries;
    j["scans_in"] = s.scans_in;
    j["scans_kept"] = s.scans_kept;
    j["dropped_pct"] = s.dropped_pct;
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
    j["points_removed_noise"] = s.points_removed_noise;
    j["max_removed_noise_share"] = s.max_removed_noise_share;  // of a kept scan's valid returns
    j["scans_surface_removed"] = s.scans_surface_removed;      // a straight run removed as noise
    j["reasons"] = nlohmann::ordered_json::object();           // scans per keep/drop reason
    for (const auto& [name, n] : s.reasons) j["reasons"][name] = n;
}

// ICP's corrections, their verdicts, re-matching and the guards under the SLAM's gate.
void icpJson(Json& j, const IcpSlamSummary& s) {
    j["icp_runs"] = s.icp_runs;
    j["icp_rejected"] = s.icp_rejected;
    j["icp_goodness_median"] = s.icp_goodness_median;
    j["lost_tracks_suspected"] = s.lost_track_stamps.size();
    j["lost_track_stamps"] = s.lost_track_stamps;
    j["scans_kept_for_recovery"] = s.scans_kept_for_recovery;
    j["rematches"] = s.rematches;
    j["rematches_recovered"] = s.rematches_recovered;
    j["scans_rematched"] = s.scans_rematched;
    j["gap_checks_failed"] = s.gap_checks_failed;
    j["guard_translation_m"] = s.guard_translation_m;  // after the SLAM's localisation gate
    j["guard_rotation_deg"] = s.guard_rotation_deg;
    j["guard_translation_m_configured"] = s.guard_translation_m_configured;  // before the gate
    j["guard_rotation_deg_configured"] = s.guard_rotation_deg_configured;
}

// The pre-filter's own counters and times, the matched drop rates, the scans before the run.
void prefilterJson(Json& j, const IcpSlamSummary& s) {
    for (const StageTotal& t : s.stage_totals) {  // the listed stages' declared counters
        if (t.value == std::floor(t.value) && std::fabs(t.value) < 9e15)
            j[t.name] = static_cast<long long>(t.value);
        else
            j[t.name] = t.value;
    }
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
    j["scans_without_step"] = s.scans_without_step;
    j["scans_before_offset"] = s.scans_before_offset;
}

// What a bag or CARMEN source repaired, laser only, what the run did not honour.
void sourceJson(Json& j, const IcpSlamSummary& s) {
    if (s.source.any()) {  // what a bag or CARMEN source repaired (absent when nothing)
        nlohmann::ordered_json src;
        src["lines_unparsable"] = s.source.lines_unparsable;
        src["bytes_unparsable"] = s.source.bytes_unparsable;
        src["first_unparsable_line"] = s.source.first_unparsable_line;
        src["scans_bad_angles"] = s.source.scans_bad_angles;
        src["stamps_zero"] = s.source.stamps_zero;
        src["scans_without_odometry"] = s.source.scans_without_odometry;
        j["source"] = std::move(src);
    }
    j["laser_only"] = s.laser_only;
    if (!s.notices.empty())  // what the run did not honour (icp-slam keys, map kinds)
        j["notices"] = s.notices;
}

// ATE and the relations error, all, local and long.
void evaluationJson(Json& j, const IcpSlamSummary& s) {
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
}

}  // namespace

std::string toJson(const IcpSlamSummary& s) {
    Json j;
    scansJson(j, s);
    icpJson(j, s);
    prefilterJson(j, s);
    sourceJson(j, s);
    evaluationJson(j, s);
    return j.dump(2) + "\n";
}

namespace {

// The keyframe guards the SLAM's localisation gate lowered (the pre-filter runs kfd's keyframe
// stage): configured -> used. Empty when none was lowered.
std::string gateText(const IcpSlamSummary& s) {
    const auto& stages = s.pipeline.stages;
    if (!defaultStageRegistry().choice("selector")->listedIn(stages)) return {};
    std::string lowered;
    if (s.guard_translation_m != s.guard_translation_m_configured)
        lowered += format("%g -> %g m", s.guard_translation_m_configured, s.guard_translation_m);
    if (s.guard_rotation_deg != s.guard_rotation_deg_configured)
        lowered += format("%s%g -> %g deg", lowered.empty() ? "" : ", ",
                          s.guard_rotation_deg_configured, s.guard_rotation_deg);
    if (lowered.empty()) return {};
    return "  guards     keyframe guards lowered to the SLAM's localisation gate: " + lowered +
           " (kfd-filter has no ICP gate: with the same [KFD] it keeps fewer scans)\n";
}

}  // namespace

std::string summaryText(const IcpSlamSummary& s) {
    std::string t = format("kfd-icp-slam summary (mode %s)\n", toString(s.mode));
    t += format("  input      %s\n  output     %s\n", s.rawlog.c_str(), s.output_dir.c_str());
    t += format("  scans      in %zu, kept %zu, dropped %.1f %% (scans not passed on, of all read)",
                s.scans_in, s.scans_kept, s.dropped_pct);
    t += s.scans_kept_for_recovery
             ? format("; %zu of the kept went to ICP for its recovery\n", s.scans_kept_for_recovery)
             : std::string("\n");
    if (const std::string n = scansNotIn(s); !n.empty()) t += "             not in: " + n + "\n";
    t += format("  points     removed %zu of %zu\n", s.points_removed, s.points_in);
    t += gateText(s);
    for (const std::string& line : reasonLines(s)) t += "  " + line + "\n";
    t += format(
        "  time       pre-filter %.1f us/scan, ICP-SLAM %.3f ms/scan, CPU %.2f s, wall %.2f s\n",
        s.prefilter_us_per_scan, s.icp_ms_per_scan, s.cpu_s_total, s.wall_s_total);
    if (s.icp_runs)
        t +=
            format("  ICP        %s, %zu rejected, median goodness %.2f\n",
                   plural(s.icp_runs, "correction").c_str(), s.icp_rejected, s.icp_goodness_median);
    if (s.rematches)
        t += format(
            "  re-match   %zu after a rejection (%zu by the gap check, %zu then accepted), %s "
            "matched again\n",
            s.rematches, s.gap_checks_failed, s.rematches_recovered,
            plural(s.scans_rematched, "dropped scan").c_str());
    if (!s.lost_track_stamps.empty())
        t += format(
            "  WARNING    %s (%zu ICP corrections rejected in a row), "
            "first at t = %.3f s: see report.md and scans.csv's icp_goodness\n",
            plural(s.lost_track_stamps.size(), "suspected lost track").c_str(),
            kLostTrackRejections, s.lost_track_stamps.front());
    if (s.ate_rmse) t += format("  ATE        RMSE %.4f m\n", *s.ate_rmse);
    if (s.relations) {
        const auto& r = *s.relations;
        t += format(
            "  relations  %zu used, %zu unmatched: trans %.4f +- %.4f m, rot %.3f +- %.3f deg\n",
            r.used, r.unmatched, r.trans_mean, r.trans_std, r.rot_mean_deg, r.rot_std_deg);
        for (const auto& [name, sub] :
             {std::pair{"local", &s.relations_local}, std::pair{"long ", &s.relations_long}})
            if (*sub)
                t += format("    %s    (%s %g s) %zu used: trans %.4f +- %.4f m\n", name,
                            sub == &s.relations_local ? "<=" : ">", s.split_seconds, (*sub)->used,
                            (*sub)->trans_mean, (*sub)->trans_std);
    }
    if (s.target_drop_pct) t += format("  matched    drop target %.2f %%\n", *s.target_drop_pct);
    return t;
}

void writeIcpSlamReport(const IcpSlamResult& result) {
    if (!result.output) throw SlamError("no staged output folder in the result");
    if (result.output->committed()) throw SlamError("the output was already committed");
    const StagedOutputFolder& out = *result.output;
    std::vector<MapFigureLayer> layers;
    if (result.map) layers = writeMap(result, out);
    throwIfCancelled();
    writeText(out, "summary.json", toJson(result.summary));
    if (result.map) writeText(out, "report.md", reportMarkdown(result.summary, layers));
    throwIfCancelled();
    result.output->commit();
}

}  // namespace kfd
