#!/usr/bin/env bash
# Issue 25 (docs/RESULTS.md, "Temporal evidence from dropped scans"): the default pipeline
# (share/kfd/default.ini: odometry check, distance, keyframe, denoise) with temporal_scans = N
# for each N in TEMPORAL (default "0 1"), on real logs with injected noise (kfd-inject, all its
# models, seed SEED, default 7) and on the clean logs. kfd-denoise-eval scores the kept scans
# only (what the SLAM sees).
# Usage: SEED=7 TEMPORAL="0 1 2" bash scripts/denoise-temporal.sh [LOG ...]
#        (default: the six logs; needs build/apps/kfd-inject and kfd-denoise-eval)
# Output: out/denoise-temporal/seedSEED/LOG-tN-{noisy,clean}.txt
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
data="${KFD_DATASETS_DIR:-$root/../shared/datasets}"
bin="$root/build/apps"
seed="${SEED:-7}"
out="$root/out/denoise-temporal/seed$seed"
for t in kfd-inject kfd-denoise-eval; do
  [ -x "$bin/$t" ] || { echo "build $t first" >&2; exit 1; }
done
mkdir -p "$out"
cd "$out"
echo "scan,timestamp,beam,kind" > empty.csv
for n in ${TEMPORAL:-0 1}; do
  { cat "$root/share/kfd/default.ini"; echo "temporal_scans = $n"; } > "t$n.ini"
done
logs=("$@")
[ ${#logs[@]} -gt 0 ] || logs=(fr079 aces intel mit-csail mines-exp1 mines-exp2)
for log in "${logs[@]}"; do
  case $log in
    mines-exp1) src="$data/mines-urg/exp1.rawlog" ;;
    mines-exp2) src="$data/mines-urg/exp2.rawlog" ;;
    *) src="$data/$log/$log.rawlog" ;;
  esac
  [ -f "$src" ] || { echo "missing: $src" >&2; continue; }
  [ -f "$log-noisy.rawlog" ] || "$bin/kfd-inject" -q -i "$src" -o "$log-noisy.rawlog" --seed "$seed" > "$log-inject.txt"
  for n in ${TEMPORAL:-0 1}; do
    "$bin/kfd-denoise-eval" -i "$log-noisy.rawlog" -l "$log-noisy.labels.csv" -c "t$n.ini" > "$log-t$n-noisy.txt"
    "$bin/kfd-denoise-eval" -i "$src" -l empty.csv -c "t$n.ini" > "$log-t$n-clean.txt"
  done
done
echo "results in $out" >&2
