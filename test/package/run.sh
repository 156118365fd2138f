#!/usr/bin/env bash
# Installs kfd from BUILD_DIR into a temporary prefix, then configures, builds and runs the
# consumer project against it. Usage: run.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build="$1"; here="$2"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
cmake -S "$here" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$tmp/prefix" >/dev/null
cmake --build "$tmp/consumer" >/dev/null
"$tmp/consumer/consumer"
echo "kfd package found, linked and ran"
