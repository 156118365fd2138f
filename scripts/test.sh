#!/usr/bin/env bash
# Installs what is missing, builds kfd with its tests, and runs the whole suite through ctest.
# Warnings are errors when CI is set (as on the CI machine).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/ci/install-deps.sh"
werror=OFF
[ -n "${CI:-}" ] && werror=ON
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKFD_BUILD_TESTS=ON \
  -DKFD_WARNINGS_AS_ERRORS=$werror >/dev/null
cmake --build "$root/build" -j"$(nproc)"
# npm's MCAP and rosbag2 readers for the ROS 2 output tests (CI: required; elsewhere they skip).
if ! bash "$root/scripts/ci/npm-peers.sh" "$root/build"; then
  [ -n "${CI:-}" ] && { echo "[kfd] CI: npm peers are required" >&2; exit 1; }
fi
cd "$root/build"
status=0
ctest --output-on-failure -j"$(nproc)" || status=$?
# The tests that skipped themselves (GTEST_SKIP, unittest's skipTest: real data or a tool
# missing), with the reason each gave: a green run with skips says so last.
log=Testing/Temporary/LastTest.log
if [ -f "$log" ]; then
  bash "$root/scripts/ci/list-skips.sh" "$log"
fi
exit $status
