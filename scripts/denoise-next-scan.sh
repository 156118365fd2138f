#!/usr/bin/env bash
# Issue 25 (docs/RESULTS.md, "The scan just after a keyframe"): the default pipeline
# (share/kfd/default.ini) with next_scan = false and true, each with max_removed_fraction =
# 0.05 (the default) and 1 (no bound: what the next scan adds on its own), on real logs with
# injected noise (kfd-inject, all its models, seed SEED) and on the clean logs. kfd-denoise-eval
# scores the kept scans only. Development runs use SEED=1 only (7 and 11 are held out).
# Usage: SEED=1 bash scripts/denoise-next-scan.sh [LOG ...]   (default: fr079 aces; needs
#        build/apps/kfd-inject and kfd-denoise-eval)
# Output: out/denoise-next-scan/seedSEED/LOG-{off,on}-bBOUND-{noisy,clean}.txt
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
data="${KFD_DATASETS_DIR:-$root/../shared/datasets}"
bin="$root/build/apps"
seed="${SEED:-1}"
out="$root/out/denoise-next-scan/seed$seed"
for t in kfd-inject kfd-denoise-eval; do
  [ -x "$bin/$t" ] || { echo "build $t first" >&2; exit 1; }
done
mkdir -p "$out"
cd "$out"
echo "scan,timestamp,beam,kind" > empty.csv
for next in off on; do
  for bound in 0.05 1; do
    { cat "$root/share/kfd/default.ini"
      echo "next_scan = $([ $next = on ] && echo true || echo false)"
      echo "max_removed_fraction = $bound"; } > "$next-b$bound.ini"
  done
done
logs=("$@")
[ ${#logs[@]} -gt 0 ] || logs=(fr079 aces)
for log in "${logs[@]}"; do
  case $log in
    mines-exp1) src="$data/mines-urg/exp1.rawlog" ;;
    mines-exp2) src="$data/mines-urg/exp2.rawlog" ;;
    *) src="$data/$log/$log.rawlog" ;;
  esac
  [ -f "$src" ] || { echo "missing: $src" >&2; continue; }
  [ -f "$log-noisy.rawlog" ] || "$bin/kfd-inject" -q -i "$src" -o "$log-noisy.rawlog" --seed "$seed" > "$log-inject.txt"
  for c in off-b0.05 on-b0.05 off-b1 on-b1; do
    "$bin/kfd-denoise-eval" -i "$log-noisy.rawlog" -l "$log-noisy.labels.csv" -c "$c.ini" > "$log-$c-noisy.txt"
    "$bin/kfd-denoise-eval" -i "$src" -l empty.csv -c "$c.ini" > "$log-$c-clean.txt"
  done
done
echo "results in $out" >&2
