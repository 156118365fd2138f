#!/usr/bin/env bash
# Variants of the default pipeline (share/kfd/default.ini with keys appended) on real logs with
# injected labelled noise (kfd-inject, all its models, seed SEED) and on the clean logs;
# kfd-denoise-eval scores the kept scans only (what the SLAM sees). Issue 25's tables in
# docs/CHANGELOG.md. Development runs use SEED=1; 7 and 11 were held out.
# Usage: SEED=11 bash scripts/experiments/denoise-variants.sh NAME[:KEY=VALUE[,KEY=VALUE...]] ... [-- LOG ...]
#   e.g. SEED=11 bash scripts/experiments/denoise-variants.sh before:max_confirmed_fraction=0 default \
#          next:next_scan=true -- fr079 aces          (default logs: the six)
# Output: out/denoise-variants/seedSEED/LOG-NAME-{noisy,clean}.txt; tables:
#   python3 scripts/experiments/denoise_variants_table.py out/denoise-variants/seedSEED NAME ...
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/real-logs.sh"
seed="${SEED:-1}"
out="$root/out/denoise-variants/seed$seed"
variants=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do variants+=("$1"); shift; done
[ $# -gt 0 ] && shift
[ ${#variants[@]} -gt 0 ] || { echo "usage: SEED=N $0 NAME[:KEY=VALUE,...] ... [-- LOG ...]" >&2; exit 2; }
logs=("$@")
[ ${#logs[@]} -gt 0 ] || logs=("${all_logs[@]}")
mkdir -p "$out"
cd "$out"
echo "scan,timestamp,beam,kind" > empty.csv
names=()
for v in "${variants[@]}"; do
  name="${v%%:*}"
  names+=("$name")
  { cat "$root/share/kfd/default.ini"
    [ "$v" = "$name" ] || tr ',' '\n' <<< "${v#*:}" | sed 's/=/ = /'; } > "$name.ini"
done
for log in "${logs[@]}"; do
  src="$(log_path "$log")"
  [ -f "$src" ] || { echo "missing: $src" >&2; continue; }
  [ -f "$log-noisy.rawlog" ] || "$bin/kfd-inject" -q -i "$src" -o "$log-noisy.rawlog" --seed "$seed" > "$log-inject.txt"
  for name in "${names[@]}"; do
    "$bin/kfd-denoise-eval" -i "$log-noisy.rawlog" -l "$log-noisy.labels.csv" -c "$name.ini" > "$log-$name-noisy.txt"
    "$bin/kfd-denoise-eval" -i "$src" -l empty.csv -c "$name.ini" > "$log-$name-clean.txt"
  done
done
echo "results in $out" >&2
