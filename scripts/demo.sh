#!/usr/bin/env bash
# The main job: installs what is missing, builds kfd, then on the bundled simulated 40 Hz log
# (or IN.rawlog) runs kfd-filter (its summary; the filtered rawlog opens in RawLogViewer) and
# kfd-icp-slam with the kfd pre-filter, which writes report.md, map_figure.png and
# summary.json; and renders one scan's clusters (kfd-render, when OSMesa is available).
# Usage: bash scripts/demo.sh [LOG [FILTER_CONFIG [SLAM_CONFIG]]]
#   LOG: a rawlog, ROS 1 or ROS 2 bag or CARMEN log (default rawlogs/office-mit-0.752.rawlog);
#   FILTER_CONFIG: default share/kfd/default.ini (one preset for every rate); SLAM_CONFIG:
#   picked by the log's scan rate (kfd-filter --list), said on stderr: 20 Hz or more
#   share/kfd-icp-slam/lidar-40hz.ini, else share/kfd-icp-slam/sick-180-5hz.ini.
#   LOG's stem.gt.tum beside it, when present, gives the ATE.
# Every file the last line names is checked; a missing one is an error (exit 1).
# KFD_DEMO_APPS=DIR: the apps already built in DIR (the test suite's check on a clean copy of
# the tree, test/scripts/demo_test.sh): no install, no build.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
apps="${KFD_DEMO_APPS:-$root/build/apps}"
render=0
if [ -n "${KFD_DEMO_APPS:-}" ]; then
  [ -x "$apps/kfd-render" ] && render=1
else
  bash "$root/scripts/ci/install-deps.sh"
  cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  targets=(kfd-filter kfd-icp-slam)
  # kfd-render exists when CMake found OSMesa (the list read whole: grep -q would close the
  # pipe early and pipefail would count the build tool's broken pipe as no kfd-render)
  help="$(cmake --build "$root/build" --target help)"
  if grep -q ' kfd-render$' <<<"$help"; then
    targets+=(kfd-render)
    render=1
  fi
  cmake --build "$root/build" -j"$(nproc)" --target "${targets[@]}"
fi
in="${1:-$root/rawlogs/office-mit-0.752.rawlog}"
cfg="${2:-$root/share/kfd/default.ini}"
base="$(basename "$in")"
name="${base%.gz}"
name="${name%.*}"  # office-mit-0.752.rawlog -> office-mit-0.752; a rosbag2 folder keeps its name
if [ -n "${3:-}" ]; then
  slam_cfg="$3"
else  # by the scan stream's rate, as kfd-filter --list gives it ("(15.0 s, 40.0 Hz)")
  rate="$("$apps/kfd-filter" --list -i "$in" |
    awk '/2D scan|LaserScan/ && !seen { for (i = 2; i <= NF; i++) if ($i == "Hz)") { print $(i-1); seen = 1 } }')"
  slam_cfg="$root/share/kfd-icp-slam/sick-180-5hz.ini"
  if awk -v r="${rate:-0}" 'BEGIN { exit !(r >= 20) }'; then
    slam_cfg="$root/share/kfd-icp-slam/lidar-40hz.ini"
  fi
  echo "[kfd] $base: scans at ${rate:-an unknown rate} Hz: kfd-filter -c ${cfg#"$root"/}," \
    "kfd-icp-slam ${slam_cfg#"$root"/} (give configs as arguments to choose)" >&2
fi
out="$root/out"
mkdir -p "$out"
start=$(date +%s)
"$apps/kfd-filter" -q -c "$cfg" -i "$in" -o "$out/$name.kfd.rawlog" \
  --stats "$out/$name.kfd.csv"
gt=()
[ -f "$(dirname "$in")/$name.gt.tum" ] && gt=(--gt "$(dirname "$in")/$name.gt.tum")
"$apps/kfd-icp-slam" -q "$slam_cfg" "$in" -o "$out/$name-slam" -m kfd "${gt[@]}"
made=("$name.kfd.rawlog" "$name.kfd.csv" "$name-slam/report.md" "$name-slam/map_figure.png"
  "$name-slam/summary.json" "$name-slam/trajectory.tum")
if [ "$render" = 1 ]; then
  "$apps/kfd-render" -i "$in" --index 300 -c "$cfg" -o "$out/$name-clusters.png" \
    --extent 8 >/dev/null
  made+=("$name-clusters.png")
else
  echo "[kfd] no OSMesa found by CMake: kfd-render not built, no scan figure" >&2
fi
for f in "${made[@]}"; do
  [ -s "$out/$f" ] || { echo "[kfd] error: the main job did not write out/$f" >&2; exit 1; }
done
figure=""
[ "$render" = 1 ] && figure="; out/$name-clusters.png"
echo "[kfd] $(( $(date +%s) - start )) s: out/$name.kfd.rawlog (RawLogViewer) and .kfd.csv;" \
  "out/$name-slam/report.md with map_figure.png, summary.json, trajectory.tum$figure"
