// The files of a kfd-icp-slam run written from its result: summary.json, the map and its
// figure, report.md.
#pragma once

#include <string>
#include <vector>

#include "kfd/plot/map_figure.h"
#include "kfd/slam/icp_slam_runner.h"

namespace kfd {

/// summary.json's text: every number of the summary, keys in a fixed order (mode, rawlog,
/// stages, entries, scans_in, scans_kept, dropped_pct, points_in, points_removed,
/// prefilter_us_per_scan, icp_ms_per_scan, icp_ms_per_kept_scan, cpu_s_total, wall_s_total,
/// motion_distance_m, motion_angle_deg, then notices, ate_rmse_m and relations when present).
std::string toJson(const IcpSlamSummary& s);

/// The summary kfd-icp-slam prints on the console: scans, points, time, ICP's verdicts,
/// re-matches, lost tracks, ATE, the relations error (all, local and long) and the matched drop
/// target, one line each.
std::string summaryText(const IcpSlamSummary& s);

/// The map figure's title: the log's file name, the mode, the drop rate, the ATE when known and
/// the suspected lost tracks ("fr079.rawlog  mode kfd  dropped 59.8 %  ATE 0.120 m  no lost
/// track").
std::string mapTitle(const IcpSlamSummary& s);

/// report.md's text: every number summaryText() prints, with its unit (the local and long
/// relations error with their counts, used and unmatched), and the map figure with a caption
/// naming exactly `figure_layers` (what renderMapFigure drew; mapFigureCaption).
std::string reportMarkdown(const IcpSlamSummary& s,
                           const std::vector<MapFigureLayer>& figure_layers);

/// Writes into result.summary.output_dir: summary.json and, when the result holds the built
/// map (IcpSlamOptions::write_map), final_map.simplemap, map.png (the occupancy grid's known
/// cells, one cell a pixel, 5 cm unless the map is very large), map_figure.png
/// (renderMapFigure: grid + estimate, keyframes, odometry and ground truth, cropped to what it
/// draws, within its pixel budget) and report.md.
/// Writes into the result's staging folder, then moves everything into output_dir
/// (IcpSlamResult::output->commit(), which checks every file first). Every file goes through
/// kfd's checked writers (OutputFile, GzOutputStream, writePng): throws WriteError ("cannot write
/// OUT/map.png: No space left on device", the file's final name) when a file cannot be written
/// completely, PathError when the folder cannot be moved into place, Cancelled after
/// kfd::requestCancel().
void writeIcpSlamReport(const IcpSlamResult& result);

}  // namespace kfd
