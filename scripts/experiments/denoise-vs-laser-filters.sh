#!/usr/bin/env bash
# kfd's denoiser against laser_filters-equivalent baselines (issue 39): kfd's default, kfd
# before issue 39 (steps 6-7 off), kfd with step 6 (veil), the paper's Algorithm 2, the
# `speckle` stage (LaserScanSpeckleFilter, distance: 80 m / 0.1 or 0.3 m / window 2), the
# `shadow` stage (10-170 deg, window 1, start point removed) and their chain, each after kfd's
# keyframes, so all are scored on the same kept scans. Injected labelled noise (kfd-inject,
# all its models, seed SEED: 13 was the development seed, use another) and the clean logs.
# Usage: SEED=3901 bash scripts/experiments/denoise-vs-laser-filters.sh [LOG ...]
# Output: out/denoise-vs-laser-filters/seedSEED/LOG-NAME-{noisy,clean}.txt; table:
#   python3 scripts/experiments/denoise_variants_table.py out/denoise-vs-laser-filters/seedSEED \
#     default before veil reference speckle01 speckle03 shadow chain
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/real-logs.sh"
seed="${SEED:-3901}"
out="$root/out/denoise-vs-laser-filters/seed$seed"
logs=("$@")
[ ${#logs[@]} -gt 0 ] || logs=("${all_logs[@]}")
mkdir -p "$out"
cd "$out"
echo "scan,timestamp,beam,kind" > empty.csv
def="$root/share/kfd/default.ini"
# after STAGES: the default pipeline with its denoiser replaced by STAGES (its section dropped).
after() { sed '/^\[KFD.evidence_denoise\]/,$d' "$def" |
  sed "s/^pipeline = .*/pipeline = odometry_check, distance, track, view_keyframe, $1/"; }
shadow=$'\n[KFD.shadow]\nshadow_min_angle_deg = 10\nshadow_max_angle_deg = 170\nshadow_window = 1\nshadow_remove_start = true\n'
cp "$def" default.ini
{ cat "$def"; printf 'veil = false\nkeep_surfaces = false\n'; } > before.ini
{ cat "$def"; printf 'veil = true\n'; } > veil.ini
{ after denoise; } > reference.ini
{ after speckle; printf '\n[KFD.speckle]\nspeckle_max_range_difference = 0.1\n'; } > speckle01.ini
{ after speckle; printf '\n[KFD.speckle]\nspeckle_max_range_difference = 0.3\n'; } > speckle03.ini
{ after shadow; printf '%s' "$shadow"; } > shadow.ini
{ after "shadow, speckle"; printf '%s\n[KFD.speckle]\nspeckle_max_range_difference = 0.3\n' "$shadow"; } > chain.ini
names=(default before veil reference speckle01 speckle03 shadow chain)
for log in "${logs[@]}"; do
  src="$(log_path "$log")"
  [ -f "$src" ] || { echo "missing: $src" >&2; continue; }
  [ -f "$log-noisy.rawlog" ] || "$bin/kfd-inject" -q -i "$src" -o "$log-noisy.rawlog" --seed "$seed" > "$log-inject.txt"
  for name in "${names[@]}"; do
    echo "$log $name" >&2
    "$bin/kfd-denoise-eval" -i "$log-noisy.rawlog" -l "$log-noisy.labels.csv" -c "$name.ini" > "$log-$name-noisy.txt"
    "$bin/kfd-denoise-eval" -i "$src" -l empty.csv -c "$name.ini" > "$log-$name-clean.txt"
  done
done
echo "results in $out" >&2
