#!/usr/bin/env bash
# Runs one libFuzzer target for N minutes: scripts/ci/fuzz.sh TARGET MINUTES
#   TARGET: pipeline, ini, yaml, rawlog, carmen, bag, mcap, db3, ros2_node or ros1_node (test/fuzz/fuzz_TARGET.cpp)
# Builds the fuzzers in build-fuzz/ (clang, KFD_BUILD_FUZZERS=ON) when needed, starts from
# the committed corpus test/fuzz/corpus/TARGET/ (new inputs go to build-fuzz/corpus/TARGET/,
# the committed one is never written), runs with -max_total_time and a 2 s timeout per input,
# and keeps going after a crash (-fork=1 -ignore_crashes=1): every crash, timeout or
# out-of-memory input is kept in build-fuzz/artifacts/TARGET/. Exit status 1 when any was kept.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
if [ $# -ne 2 ]; then
  echo "usage: $0 TARGET MINUTES   (TARGET: pipeline, ini, yaml, rawlog, carmen, bag, mcap, db3, ros2_node, ros1_node)" >&2
  exit 2
fi
target="$1"
minutes="$2"
build="$root/build-fuzz"
if [ ! -x "$build/test/fuzz/fuzz_$target" ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DKFD_BUILD_FUZZERS=ON -DKFD_BUILD_TESTS=OFF -DKFD_BUILD_APPS=OFF -DKFD_BUILD_RENDER=OFF \
    -DKFD_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build "$build" -j2 --target "fuzz_$target"
fi
corpus="$build/corpus/$target"
artifacts="$build/artifacts/$target"
mkdir -p "$corpus" "$artifacts"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# ASan's default fast (frame-pointer) unwinding on malloc: full stacks (fast_unwind_on_malloc=0)
# cut every target's rate 2-7 times (fuzz_bag 150 -> 22 inputs/s, docs/CHANGELOG.md). The leak
# suppressions name third-party libraries, and the allocating frame, always recorded, is in them.
# allocator_may_return_null: an impossible malloc returns null, as glibc's does, instead of
# stopping the run: OpenCV's images (an image observation in a rawlog) allocate with malloc,
# outside kfd's allocation bound, and turn a null into an exception (kfd: a clear error).
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=1"
export LSAN_OPTIONS="suppressions=$root/scripts/ci/lsan.supp:print_suppressions=0"
rc=0
"$build/test/fuzz/fuzz_$target" -max_total_time=$((minutes * 60)) -timeout=2 -rss_limit_mb=2048 \
  -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 -print_final_stats=1 \
  -artifact_prefix="$artifacts/" "$corpus" "$root/test/fuzz/corpus/$target" || rc=$?
n=$(find "$artifacts" -type f | wc -l)
echo "fuzz_$target: $minutes min, libFuzzer exit status $rc, $n input(s) kept in $artifacts"
[ "$n" -eq 0 ]
