#!/usr/bin/env bash
# The README's first command on a clean copy of the tree (its tracked files, as a fresh clone
# has them: no build, no out/): scripts/demo.sh with the apps of this build (KFD_DEMO_APPS)
# exits 0, and every out/ file its last line names exists and is not empty.
# Usage: demo_test.sh SOURCE_DIR APPS_DIR
set -euo pipefail
src="$1"
apps="$2"
tmp="$(mktemp -d "${TMPDIR:-/tmp}/kfd_demo_test.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/kfd"
if git -C "$src" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  (cd "$src" && git ls-files -z | tar --null -T - -cf -) | tar -xf - -C "$tmp/kfd"
else  # a source tree without git: everything but build folders and outputs
  (cd "$src" && tar --exclude='./build*' --exclude='./out' -cf - .) | tar -xf - -C "$tmp/kfd"
fi
[ ! -e "$tmp/kfd/out" ] || { echo "FAIL: the copy already has out/"; exit 1; }
log="$tmp/demo.log"
if ! KFD_DEMO_APPS="$apps" bash "$tmp/kfd/scripts/demo.sh" >"$log" 2>&1; then
  echo "FAIL: demo.sh exited non-zero"; cat "$log"; exit 1
fi
last="$(tail -n 1 "$log")"
echo "$last"
# "out/X.kfd.rawlog (...) and .kfd.csv; out/D/report.md with a, b, c; out/Y.png"
named=()
for tok in $(grep -o 'out/[^ ;,()]*' <<<"$last"); do named+=("$tok"); done
base="$(grep -o 'out/[^ ;,()]*\.kfd\.rawlog' <<<"$last" | head -n 1)"
[ -n "$base" ] && grep -q 'and \.kfd\.csv' <<<"$last" && named+=("${base%.rawlog}.csv")
report="$(grep -o 'out/[^ ;,()]*/report\.md' <<<"$last" | head -n 1)"
if [ -n "$report" ]; then
  for f in $(sed -n 's/.*report\.md with \([^;]*\).*/\1/p' <<<"$last" | tr -d ','); do
    named+=("$(dirname "$report")/$f")
  done
fi
[ "${#named[@]}" -ge 7 ] || { echo "FAIL: the last line names ${#named[@]} files: $last"; exit 1; }
status=0
for f in "${named[@]}"; do
  if [ -s "$tmp/kfd/$f" ]; then echo "ok   $f"; else echo "FAIL $f missing or empty"; status=1; fi
done
exit $status
