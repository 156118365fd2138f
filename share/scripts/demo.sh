#!/usr/bin/env bash
# Installs what is missing, builds kfd, and runs kfd-filter on a default input.
# Usage: bash share/scripts/demo.sh [IN.rawlog] [CONFIG]
# (for a 5 Hz log such as MRPT's sample, use share/kfd/default.ini as CONFIG)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bash "$root/share/scripts/install-deps.sh"
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$root/build" --target kfd-filter -j"$(nproc)"
# Default input: the bundled simulated 40 Hz log (ground truth and noise labels beside it).
in="${1:-$root/rawlogs/office-mit-0.752.rawlog}"
cfg="${2:-$root/share/kfd/kfd-40hz.ini}"
mkdir -p "$root/out"
name="$(basename "$in" .rawlog)"
"$root/build/apps/kfd-filter" -c "$cfg" -i "$in" -o "$root/out/$name.kfd.rawlog" \
  --stats "$root/out/$name.kfd.csv"
echo "[kfd] wrote out/$name.kfd.rawlog and out/$name.kfd.csv (open the rawlog in RawLogViewer)"
