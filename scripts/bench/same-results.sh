#!/usr/bin/env bash
# Checks that a change left kfd's results as they were: runs the tools of two builds (e.g. the
# last landed commit's and the working tree's) on the real logs and compares what they write.
#   kfd-filter    every format (rawlog, ROS 1 bag, CARMEN): the output (decompressed), the
#                 summary (but paths and times), the per-scan decisions (kept, reason); the
#                 paper's presets on two logs (every per-scan column but the time)
#   kfd-icp-slam  a few modes and options: trajectory.tum, log_estimated_path.txt, summary.json
#                 (but times and paths)
#   kfd-render    one scan's figure (PNG bytes)
#   kfd-inject    the noisy log and its labels, then kfd-denoise-eval's scores (but times)
# Prints one line per check ("same" or "DIFF") and exits 1 when anything differs.
#
# Usage: bash scripts/bench/same-results.sh OLD_BUILD NEW_BUILD [DATASETS_DIR]
# e.g.   git worktree add ../kfd-old HEAD && cmake -S ../kfd-old -B ../kfd-old/build && \
#        cmake --build ../kfd-old/build -j2 --target kfd-filter kfd-icp-slam kfd-render \
#          kfd-inject kfd-denoise-eval && bash scripts/bench/same-results.sh ../kfd-old/build build
set -euo pipefail
[ $# -ge 2 ] || { sed -n '2,15p' "$0" >&2; exit 2; }
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
old="$(cd "$1" && pwd)" new="$(cd "$2" && pwd)"
data="${3:-$root/../shared/datasets}"
sena="/usr/share/mrpt/datasets/2006-01ENE-21-SENA_Telecom Faculty_one_loop_only.rawlog"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
status=0
verdict() {  # label, then a command that succeeds when both sides agree
  local label="$1"
  shift
  if "$@" >/dev/null 2>&1; then echo "same  $label"; else echo "DIFF  $label"; status=1; fi
}
same_file() { cmp -s "$1" "$2"; }
# Each build with its own tree's configuration (a change may respell it: issue 34's stage names).
src_of() { sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$1/CMakeCache.txt"; }
same_gz() { cmp -s <(zcat "$1") <(zcat "$2"); }
same_text() { diff <(grep -Ev "$3" "$1") <(grep -Ev "$3" "$2"); }
same_cols() { diff <(tail -n +2 "$1" | cut -d, -f"$3") <(tail -n +2 "$2" | cut -d, -f"$3"); }  # no header
# By name (issue 34: the per-scan CSV holds the listed stages' declared columns only; the
# counters in summary.json are the listed stages').
same_named_cols() { python3 "$root/scripts/bench/same_outputs.py" csv "$@"; }
same_json() { python3 "$root/scripts/bench/same_outputs.py" json "$@"; }
# kfd-filter's summary: issue 34 prints each listed stage's declared counters on a line of its
# own ("  view_keyframe: ...") in place of the corridor, odometry and bound lines; their values
# are compared in kfd-icp-slam's summary.json.
summary_of() {
  sed -E -e '/^  (corridor|odometry withheld) /d' -e '/^  [a-z_0-9]+: /d' \
    -e 's/; the bound on removal acted on .*$//' -e 's/; above the bound but confirmed .*$//' "$1" |
    grep -Ev '^  (output|time) '
}
same_summary() { diff <(summary_of "$1") <(summary_of "$2"); }

# kfd-filter: every input format.
for spec in aces/aces.rawlog intel/intel.rawlog fr079/fr079.rawlog mit-csail/mit-csail.rawlog \
  mit-killian/mit-killian.rawlog mines-urg/exp1.rawlog aces/aces.orig.bag ccny-urg/demo.bag \
  mit-csail/mit-csail.clf fr079/fr079.reconstructed.clf.gz; do
  in="$data/$spec"
  [ -f "$in" ] || { echo "skip  $spec (missing)"; continue; }
  n="${spec//\//_}"
  ext=rawlog opt=()
  # A bag output in lz4 on both sides (the default became the input's compression in issue 23).
  case "$spec" in *.bag) ext=bag opt=(--bag-compression lz4) ;; esac
  for side in old new; do
    b="$old"
    [ $side = new ] && b="$new"
    "$b/apps/kfd-filter" -q -i "$in" -o "$tmp/$side-$n.$ext" --stats "$tmp/$side-$n.csv" \
      "${opt[@]}" >"$tmp/$side-$n.txt" 2>&1
  done
  if [ $ext = bag ]; then
    verdict "kfd-filter $spec: output bag" same_file "$tmp/old-$n.$ext" "$tmp/new-$n.$ext"
  else
    verdict "kfd-filter $spec: output rawlog" same_gz "$tmp/old-$n.$ext" "$tmp/new-$n.$ext"
  fi
  verdict "kfd-filter $spec: summary" same_summary "$tmp/old-$n.txt" "$tmp/new-$n.txt"
  verdict "kfd-filter $spec: per-scan decisions" same_cols "$tmp/old-$n.csv" "$tmp/new-$n.csv" 1-5
done

# The paper's presets (issue 34: the paper's stages run only the paper), each build with its own
# tree's preset: the output, the summary and every per-scan column but the time.
for preset in paper-mit-0.752 paper-mit-0.575; do
  for spec in mit-csail/mit-csail.rawlog fr079/fr079.rawlog; do
    in="$data/$spec"
    [ -f "$in" ] || continue
    n="$preset-${spec//\//_}"
    for side in old new; do
      b="$old"
      [ $side = new ] && b="$new"
      "$b/apps/kfd-filter" -q -i "$in" -o "$tmp/$side-$n.rawlog" --stats "$tmp/$side-$n.csv" \
        -c "$(src_of "$b")/share/kfd/$preset.ini" >"$tmp/$side-$n.txt" 2>&1 || true
    done
    verdict "kfd-filter $preset $spec: output rawlog" same_gz "$tmp/old-$n.rawlog" "$tmp/new-$n.rawlog"
    verdict "kfd-filter $preset $spec: summary" same_summary "$tmp/old-$n.txt" "$tmp/new-$n.txt"
    verdict "kfd-filter $preset $spec: per-scan rows" same_named_cols "$tmp/old-$n.csv" \
      "$tmp/new-$n.csv" microseconds
  done
done

# kfd-icp-slam: modes, a matched drop rate, laser only, a bag, a skipped start.
cfg_old="$(src_of "$old")/share/kfd-icp-slam/sick-180-5hz.ini"
cfg_new="$(src_of "$new")/share/kfd-icp-slam/sick-180-5hz.ini"
slam() {  # name, log, options...
  local name="$1" log="$2"
  shift 2
  [ -f "$log" ] || { echo "skip  kfd-icp-slam $name (missing)"; return; }
  "$old/apps/kfd-icp-slam" "$cfg_old" "$log" -o "$tmp/slam-old-$name" -q --no-map "$@" \
    >/dev/null 2>&1 || true  # a failure shows as DIFF below
  "$new/apps/kfd-icp-slam" "$cfg_new" "$log" -o "$tmp/slam-new-$name" -q --no-map "$@" \
    >/dev/null 2>&1 || true
  for f in trajectory.tum log_estimated_path.txt; do
    verdict "kfd-icp-slam $name: $f" same_file "$tmp/slam-old-$name/$f" "$tmp/slam-new-$name/$f"
  done
  # Issue 34: `_configured` added; the default stages renamed (view_keyframe, evidence_denoise),
  # compared under their old names.
  sed -e 's/"view_keyframe"/"keyframe"/; s/"evidence_denoise"/"denoise"/' \
    "$tmp/slam-new-$name/summary.json" >"$tmp/slam-new-$name/summary.renamed.json" 2>/dev/null || true
  verdict "kfd-icp-slam $name: summary.json" same_json "$tmp/slam-old-$name/summary.json" \
    "$tmp/slam-new-$name/summary.renamed.json" '_s_|_us_|_ms_|wall|cpu|output|seconds|_configured"'
  verdict "kfd-icp-slam $name: scans.csv" same_named_cols "$tmp/slam-old-$name/scans.csv" \
    "$tmp/slam-new-$name/scans.csv" microseconds
}
slam aces-kfd "$data/aces/aces.rawlog" -g "$data/aces/aces.relations"
slam aces-odometry "$data/aces/aces.rawlog" -m odometry --match-drop-of kfd
slam aces-bag-decimate "$data/aces/aces.orig.bag" -m decimate --match-drop-of kfd --laser-only \
  --skip-scans 3
slam mit-csail-kfd "$data/mit-csail/mit-csail.rawlog" -g "$data/mit-csail/mit-csail.relations" \
  --skip-scans 2
slam ccny-kfd "$data/ccny-urg/demo.bag"
slam sena-none "$sena" -m none

# kfd-render: the README's scan and a real one (evidence denoiser, history).
render() {  # name, log, index, options...
  local name="$1" log="$2" index="$3"
  shift 3
  local cfg=()
  [ -n "${RENDER_CFG:-}" ] && cfg=(-c "$(src_of "$old")/$RENDER_CFG")
  "$old/apps/kfd-render" -i "$log" --index "$index" -o "$tmp/old-$name.png" "${cfg[@]}" "$@" \
    >/dev/null 2>&1 || true
  [ -n "${RENDER_CFG:-}" ] && cfg=(-c "$(src_of "$new")/$RENDER_CFG")
  "$new/apps/kfd-render" -i "$log" --index "$index" -o "$tmp/new-$name.png" "${cfg[@]}" "$@" \
    >/dev/null 2>&1 || true
  verdict "kfd-render $name" same_file "$tmp/old-$name.png" "$tmp/new-$name.png"
}
RENDER_CFG=share/kfd/default.ini render office "$root/rawlogs/office-mit-0.752.rawlog" 300 \
  --extent 8
[ -f "$data/fr079/fr079.rawlog" ] && render fr079 "$data/fr079/fr079.rawlog" 1200

# kfd-inject and kfd-denoise-eval on a real log.
if [ -f "$data/intel/intel.rawlog" ]; then
  for side in old new; do
    b="$old"
    [ $side = new ] && b="$new"
    "$b/apps/kfd-inject" -i "$data/intel/intel.rawlog" -o "$tmp/inj-$side.rawlog" >/dev/null 2>&1
    "$b/apps/kfd-denoise-eval" -i "$tmp/inj-$side.rawlog" -l "$tmp/inj-$side.labels.csv" \
      -c "$(src_of "$b")/share/kfd/default.ini" >"$tmp/de-$side.txt" 2>&1 || true
  done
  verdict "kfd-inject intel: noisy log" same_gz "$tmp/inj-old.rawlog" "$tmp/inj-new.rawlog"
  verdict "kfd-inject intel: labels" same_file "$tmp/inj-old.labels.csv" "$tmp/inj-new.labels.csv"
  verdict "kfd-denoise-eval intel: scores" same_text "$tmp/de-old.txt" "$tmp/de-new.txt" \
    'us_per_scan|time'
fi
exit $status
