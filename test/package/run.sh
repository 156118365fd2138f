#!/usr/bin/env bash
# Installs kfd from BUILD_DIR into a temporary prefix, checks the installed kfd-compare, then
# configures, builds and runs the consumer project against it. Usage: run.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$1"; here="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
# The installed kfd-compare finds its Python package, the installed kfd-icp-slam and preset.
out="$("$tmp/prefix/bin/kfd-compare" run --logs no-such-log --repeats 1 --out "$tmp/c" 2>&1 || true)"
echo "$out" | grep -q "log not found: no-such-log" || { echo "installed kfd-compare: $out" >&2; exit 1; }
cmake -S "$here" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$tmp/prefix" >/dev/null
cmake --build "$tmp/consumer" >/dev/null
"$tmp/consumer/consumer"
echo "kfd package found, linked and ran"
