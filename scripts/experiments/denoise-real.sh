#!/usr/bin/env bash
# Denoisers on real scans with injected labelled noise (the issue-11 tables of docs/CHANGELOG.md,
# "On real scans with injected noise"): kfd-inject adds noise to each real log (seed 2), then
# kfd-denoise-eval scores every method on the noisy copy and on the clean log. Every method
# runs alone (pipeline = the method), with share/kfd/default.ini's parameters.
# Usage: bash scripts/experiments/denoise-real.sh [LOG ...]   (default: all six; after demo.sh built)
# Output: out/denoise-real/LOG-METHOD-{noisy,clean}.txt
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/real-logs.sh"
out="$root/out/denoise-real"
mkdir -p "$out"
cd "$out"
echo "scan,timestamp,beam,kind" > empty.csv
# Over kfd's defaults (what a file leaves out keeps share/kfd/default.ini's value), each
# method's own stage listed alone and its keys in its section (issue 34).
for v in reference range_aware evidence; do
  st=$([ $v = reference ] && echo denoise || { [ $v = evidence ] && echo evidence_denoise || echo range_aware_denoise; })
  printf "[KFD]\npipeline = %s\n[KFD.%s]\n" "$st" "$st" > "$v.ini"
done
# The evidence variant with the pose margins it was first given (narrower than the default).
{ cat evidence.ini; printf "pose_trans_error_m = 0.02\npose_rot_error_deg = 0.5\nmotion_error_fraction = 0.1\n"; } > evidence_narrow.ini
for st in dbscan radius sor shadow; do printf "[KFD]\npipeline = %s\n[KFD.%s]\n" "$st" "$st" > "$st.ini"; done
{ cat shadow.ini; echo "shadow_neighbors = 1"; } > shadow1.ini
logs=("$@")
[ ${#logs[@]} -gt 0 ] || logs=("${all_logs[@]}")
for log in "${logs[@]}"; do
  src="$(log_path "$log")"
  [ -f "$src" ] || { echo "missing: $src" >&2; continue; }
  echo "== $log" >&2
  [ -f "$log-noisy.rawlog" ] || "$bin/kfd-inject" -q -i "$src" -o "$log-noisy.rawlog" --seed 2 > "$log-inject.txt"
  for m in reference range_aware evidence evidence_narrow shadow1 shadow radius sor dbscan; do
    "$bin/kfd-denoise-eval" -i "$log-noisy.rawlog" -l "$log-noisy.labels.csv" -c "$m.ini" > "$log-$m-noisy.txt"
    "$bin/kfd-denoise-eval" -i "$src" -l empty.csv -c "$m.ini" > "$log-$m-clean.txt"
  done
  "$bin/kfd-denoise-eval" -i "$log-noisy.rawlog" -l "$log-noisy.labels.csv" -c evidence.ini --laser-only > "$log-evidence_lo-noisy.txt"
  "$bin/kfd-denoise-eval" -i "$src" -l empty.csv -c evidence.ini --laser-only > "$log-evidence_lo-clean.txt"
done
echo "results in $out" >&2
