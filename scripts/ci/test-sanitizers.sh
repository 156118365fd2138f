#!/usr/bin/env bash
# The sanitizer job: builds kfd with clang, AddressSanitizer + UndefinedBehaviorSanitizer
# (float-cast-overflow included, which GCC's UBSan lacks; -fno-sanitize-recover=all so any UB
# fails its test) in build-asan/, with the libFuzzer targets (their corpus replay is part of
# ctest) and without the benchmarks, then runs the whole test suite through ctest.
# Leak reports are suppressed only for third-party code, listed with reasons in
# scripts/ci/lsan.supp. Prints the time the job took.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
start=$(date +%s)
bash "$root/scripts/ci/install-deps.sh"
build="$root/build-asan"
# Fast (frame-pointer) unwinding on malloc, ASan's default: the slow unwinder calls libgcc's
# _Unwind_Find_FDE, which mallocs, and deadlocks against OSMesa's llvmpipe threads (the render
# tests hung idle at 0 % CPU with fast_unwind_on_malloc=0).
# allocator_may_return_null: an impossible malloc (a corrupt image size in a rawlog asks OpenCV
# for 1.2e18 bytes) returns null as glibc's does, and the apps report it, instead of ASan
# stopping the process (the bad-input row CorruptLength.FuzzFindingsAreClearErrors).
export ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:allocator_may_return_null=1"
export LSAN_OPTIONS="suppressions=$root/scripts/ci/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# Warnings are not errors here: clang's -Wconversion also warns of sign conversions that the
# GCC build (the one with -Werror) does not check.
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DKFD_BUILD_TESTS=ON -DKFD_BUILD_FUZZERS=ON -DKFD_BUILD_BENCHMARKS=OFF \
  -DKFD_WARNINGS_AS_ERRORS=OFF >/dev/null
if ! cmake --build "$build" -j"$(nproc)" >"$build/build.log" 2>&1; then
  grep -E "error|Error" -A5 "$build/build.log" | head -200
  exit 1
fi
# package_consumer is left to the normal job: it builds a GCC project against the installed
# (here instrumented) static libraries, which would need the sanitizer runtimes too.
cd "$build" && ctest --output-on-failure -j"$(nproc)" -E '^package_consumer$'
echo "[kfd] sanitizer job: $(( $(date +%s) - start )) s"
