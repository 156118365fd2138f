#!/usr/bin/env bash
# The main job: installs what is missing, builds kfd, then on the bundled simulated 40 Hz log
# (or IN.rawlog) runs kfd-filter (its summary; the filtered rawlog opens in RawLogViewer) and
# kfd-icp-slam with the kfd pre-filter, which writes report.md, map_figure.png and
# summary.json; and renders one scan's clusters (kfd-render, when OSMesa is available).
# Usage: bash scripts/demo.sh [IN.rawlog [FILTER_CONFIG [SLAM_CONFIG]]]
#   defaults: rawlogs/office-mit-0.752.rawlog, share/kfd/kfd-40hz.ini,
#   share/kfd-icp-slam/lidar-40hz.ini (for a 5 Hz log: share/kfd/default.ini and
#   share/kfd-icp-slam/sick-180-5hz.ini). IN.gt.tum beside the log, when present, gives the ATE.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/install-deps.sh"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
targets=(kfd-filter kfd-icp-slam)
cmake --build "$root/build" --target help | grep -q ' kfd-render$' && targets+=(kfd-render)
cmake --build "$root/build" -j"$(nproc)" --target "${targets[@]}"
in="${1:-$root/rawlogs/office-mit-0.752.rawlog}"
cfg="${2:-$root/share/kfd/kfd-40hz.ini}"
slam_cfg="${3:-$root/share/kfd-icp-slam/lidar-40hz.ini}"
name="$(basename "$in" .rawlog)"
out="$root/out"
mkdir -p "$out"
start=$(date +%s)
"$root/build/apps/kfd-filter" -q -c "$cfg" -i "$in" -o "$out/$name.kfd.rawlog" \
  --stats "$out/$name.kfd.csv"
gt=()
[ -f "${in%.rawlog}.gt.tum" ] && gt=(--gt "${in%.rawlog}.gt.tum")
"$root/build/apps/kfd-icp-slam" -q "$slam_cfg" "$in" -o "$out/$name-slam" -m kfd "${gt[@]}"
if [ -x "$root/build/apps/kfd-render" ]; then
  "$root/build/apps/kfd-render" -i "$in" --index 300 -c "$cfg" -o "$out/$name-clusters.png" \
    --extent 8 >/dev/null
fi
echo "[kfd] $(( $(date +%s) - start )) s: out/$name.kfd.rawlog (RawLogViewer) and .kfd.csv;" \
  "out/$name-slam/report.md with map_figure.png, summary.json, trajectory.tum;" \
  "out/$name-clusters.png"
