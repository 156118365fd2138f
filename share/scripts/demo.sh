#!/usr/bin/env bash
# Installs what is missing, builds kfd, and runs kfd-filter on a default input.
# Usage: bash share/scripts/demo.sh [IN.rawlog] [CONFIG]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bash "$root/share/scripts/install-deps.sh"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$root/build" --target kfd-filter -j"$(nproc)"
in="${1:-/usr/share/mrpt/datasets/2006-01ENE-21-SENA_Telecom Faculty_one_loop_only.rawlog}"
cfg="${2:-$root/share/kfd/default.ini}"
mkdir -p "$root/out"
name="$(basename "$in" .rawlog)"
"$root/build/apps/kfd-filter" -c "$cfg" -i "$in" -o "$root/out/$name.kfd.rawlog" \
  --stats "$root/out/$name.kfd.csv"
echo "[kfd] wrote out/$name.kfd.rawlog and out/$name.kfd.csv (open the rawlog in RawLogViewer)"
