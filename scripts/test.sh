#!/usr/bin/env bash
# Installs what is missing, builds kfd with its tests, and runs the whole suite through ctest.
# Warnings are errors when CI is set (as on the CI machine).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/install-deps.sh"
werror=OFF
[ -n "${CI:-}" ] && werror=ON
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKFD_BUILD_TESTS=ON \
  -DKFD_WARNINGS_AS_ERRORS=$werror >/dev/null
cmake --build "$root/build" -j"$(nproc)"
cd "$root/build" && ctest --output-on-failure -j"$(nproc)"
