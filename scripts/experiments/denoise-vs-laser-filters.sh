#!/usr/bin/env bash
# kfd's denoiser against laser_filters-equivalent baselines (issue 39): kfd's default, kfd
# before issue 39 (steps 4b, 6-7 off), kfd with the tracker's poses (tracked), kfd with step 6
# (veil), the paper's Algorithm 2, the `speckle` stage (LaserScanSpeckleFilter, distance: 80 m / 0.1 or 0.3 m / window 2), the
# `shadow` stage (10-170 deg, window 1, start point removed) and their chain, each after kfd's
# keyframes, so all are scored on the same kept scans. Injected labelled noise (kfd-inject,
# all its models, seed SEED: 13 was the development seed, use another) and the clean logs.
# Usage: SEED=3901 bash scripts/experiments/denoise-vs-laser-filters.sh [LOG ...]
#        ONLY="default tracked" ...: only these configurations.
#        SWEEP=1 SEED=3901 bash ...: also a grid of the baselines (speckle distance and radius
#        tests, shadow angles, neighbours and start point, their chain), for the issue's "no
#        configuration that keeps as many real points finds more": laser_filters_sweep.py.
# The shadow rows use neighbours 0 (laser_filters' value when the parameter is not given) unless
# named -nNN; shadow20 is the example configuration's 20 neighbours.
# Output: out/denoise-vs-laser-filters/seedSEED/LOG-NAME-{noisy,clean}.txt; tables:
#   python3 scripts/experiments/denoise_variants_table.py out/denoise-vs-laser-filters/seedSEED \
#     default tracked before veil reference speckle01 speckle03 shadow shadow20 chain
#   python3 scripts/experiments/laser_filters_sweep.py out/denoise-vs-laser-filters/seedSEED
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
# shadow_section MIN NEIGHBOURS START: the [KFD.shadow] section (max angle 180 - MIN, window 1).
shadow_section() {
  printf '\n[KFD.shadow]\nshadow_min_angle_deg = %s\nshadow_max_angle_deg = %s\nshadow_window = 1\n' \
    "$1" "$((180 - $1))"
  printf 'shadow_neighbors = %s\nshadow_remove_start = %s\n' "$2" "$3"
}
# speckle_section DIFF WINDOW [true]: the [KFD.speckle] section (distance test, or radius).
speckle_section() {
  printf '\n[KFD.speckle]\nspeckle_max_range_difference = %s\nspeckle_window = %s\nspeckle_radius = %s\n' \
    "$1" "$2" "${3:-false}"
}
cp "$def" default.ini
{ cat "$def"; printf 'veil = false\nkeep_surfaces = false\nspikes = false\n'; } > before.ini
{ cat "$def"; printf 'track_alignment = true\n'; } > tracked.ini
{ cat "$def"; printf 'veil = true\n'; } > veil.ini
{ after denoise; } > reference.ini
{ after speckle; speckle_section 0.1 2; } > speckle01.ini
{ after speckle; speckle_section 0.3 2; } > speckle03.ini
{ after shadow; shadow_section 10 0 true; } > shadow.ini
{ after shadow; shadow_section 10 20 true; } > shadow20.ini
{ after "shadow, speckle"; shadow_section 10 0 true; speckle_section 0.3 2; } > chain.ini
names=(default before tracked veil reference speckle01 speckle03 shadow shadow20 chain)
if [ "${SWEEP:-0}" = 1 ]; then
  for d in 0.03 0.05 0.1 0.2 0.3 0.5 1.0; do
    for w in 2 3; do { after speckle; speckle_section $d $w; } > "sw-speckle-d$d-w$w.ini"; done
  done
  for d in 0.1 0.2 0.3; do
    for w in 1 2; do { after speckle; speckle_section $d $w true; } > "sw-radius-d$d-w$w.ini"; done
  done
  for a in 5 10 15; do
    { after shadow; shadow_section $a 0 true; } > "sw-shadow-a$a-n0-start.ini"
    { after shadow; shadow_section $a 5 true; } > "sw-shadow-a$a-n5-start.ini"
    { after shadow; shadow_section $a 20 true; } > "sw-shadow-a$a-n20-start.ini"
    { after shadow; shadow_section $a 20 false; } > "sw-shadow-a$a-n20.ini"
    for d in 0.1 0.3; do
      { after "shadow, speckle"; shadow_section $a 0 true; speckle_section $d 2; } > "sw-chain-a$a-d$d.ini"
    done
  done
  for f in sw-*.ini; do names+=("${f%.ini}"); done
fi
[ -z "${ONLY:-}" ] || read -ra names <<< "$ONLY"
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
