#!/usr/bin/env bash
# Installs the tests' independent readers of kfd's ROS 2 outputs (npm: @mcap/core,
# @foxglove/rosbag2 and their CDR reader; versions pinned in test/support/node/package.json) into
# BUILD/npm-peers. Needs node and npm, and the npm registry. Already there: nothing to do.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
dest="${1:-$root/build}/npm-peers"
if [ -f "$dest/node_modules/@mcap/core/package.json" ] &&
   cmp -s "$root/test/support/node/package.json" "$dest/package.json"; then
  exit 0
fi
if ! command -v npm >/dev/null; then
  echo "[kfd] npm not found: the ROS 2 output tests that use npm's readers will skip" >&2
  exit 1
fi
mkdir -p "$dest"
cp "$root/test/support/node/package.json" "$dest/package.json"
(cd "$dest" && npm install --no-audit --no-fund --loglevel=error >/dev/null)
echo "[kfd] npm peers installed in $dest" >&2
