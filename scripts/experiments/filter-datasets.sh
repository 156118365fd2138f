#!/usr/bin/env bash
# Runs kfd-filter with one preset on the five Freiburg benchmark logs and prints a Markdown
# table (the source of the kfd-filter table in docs/RESULTS.md).
# Usage: bash scripts/experiments/filter-datasets.sh [CONFIG] [DATASETS_DIR]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cfg="${1:-$root/share/kfd/default.ini}"
data="${2:-$root/../shared/datasets}"
exe="$root/build/apps/kfd-filter"
[ -x "$exe" ] || { echo "build kfd-filter first (bash scripts/demo.sh)" >&2; exit 1; }
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "Preset: \`$(realpath --relative-to="$root" "$cfg")\`"
echo
echo "| dataset | scans in | kept | dropped | valid points in | removed out of range | removed as noise | wall (s) | filter (us/scan) |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
for d in mit-csail intel aces fr079 mit-killian; do
  in="$data/$d/$d.rawlog"
  [ -f "$in" ] || { echo "| $d | missing: $in |||||||" ; continue; }
  out="$("$exe" -q -c "$cfg" -i "$in" -o "$tmp/$d.rawlog")"
  echo "$out" | awk -v name="$d" '
    /^  scans/  { gsub(/,/, ""); nin=$3; kept=$5; drop=$7; pct=$8; gsub(/\(/, "", pct) }
    /^  points/ { gsub(/[,;]/, ""); pts=$3; rng=$8; noise=$12 }
    /^  time/   { gsub(/[,(]/, ""); wall=$3; us=$8 }
    END { printf "| %s | %s | %s | %s (%s %%) | %s | %s | %s | %s | %s |\n", name, nin, kept, drop, pct, pts, rng, noise, wall, us }'
done
