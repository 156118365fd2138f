#!/usr/bin/env bash
# Lists the tests of a ctest run that skipped themselves, with the reason each gave, and says
# how many: scripts/ci/list-skips.sh build/Testing/Temporary/LastTest.log (test.sh ends with it).
# GoogleTest's GTEST_SKIP() ("file:line: Skipped", the message on the next line, then
# "[  SKIPPED ] Suite.Test (N ms)") and Python unittest's skipTest ("name (...) ... skipped 'why'").
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: list-skips.sh LastTest.log" >&2; exit 2; }
awk '/: Skipped$/ { getline reason; next_reason = reason }
     /^\[  SKIPPED \] [^ ]+ \(/ {
       n++; printf "  %s: %s\n", $4, next_reason == "" ? "(no reason given)" : next_reason
       next_reason = "" }
     / \.\.\. skipped / { n++; r = $0; sub(/.* \.\.\. skipped /, "", r); printf "  %s: %s\n", $1, r }
     END { if (n) printf "%d test%s skipped (above: why; the real logs are read from cmake " \
                         "-DKFD_DATASETS_DIR, default ../shared/datasets)\n", n, n == 1 ? "" : "s"
           else print "no test skipped" }' "$1"
