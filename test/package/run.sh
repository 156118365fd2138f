#!/usr/bin/env bash
# Installs kfd from BUILD_DIR into a temporary prefix, checks the installed kfd-compare, then
# configures, builds and runs the consumer project and the library example (examples/filter_log)
# against it. Usage: run.sh BUILD_DIR PACKAGE_TEST_DIR PROJECT_SOURCE_DIR
set -euo pipefail
build="$1"; here="$2"; src="$3"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
# The installed kfd-compare finds its Python package, the installed kfd-icp-slam and preset.
out="$("$tmp/prefix/bin/kfd-compare" run --logs no-such-log --repeats 1 --out "$tmp/c" 2>&1 || true)"
echo "$out" | grep -q "log not found: no-such-log" || { echo "installed kfd-compare: $out" >&2; exit 1; }
cmake -S "$here" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$tmp/prefix" >/dev/null
cmake --build "$tmp/consumer" >/dev/null
"$tmp/consumer/consumer"
# Without ROS: find_package(kfd) and kfd::mrpt need none of ROS 1's bag libraries or headers
# (here made unfindable); the component bag asks for them (its REQUIRED form fails then).
cmake -S "$here" -B "$tmp/no-ros" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
  -DCMAKE_DISABLE_FIND_PACKAGE_KfdRos1=TRUE -DCMAKE_DISABLE_FIND_PACKAGE_KfdRosNode=TRUE >/dev/null
cmake --build "$tmp/no-ros" --target consumer >/dev/null
"$tmp/no-ros/consumer"
mkdir -p "$tmp/bag-needs-ros"
printf 'cmake_minimum_required(VERSION 3.22)\nproject(p LANGUAGES CXX)\nfind_package(kfd REQUIRED COMPONENTS bag)\n' \
  >"$tmp/bag-needs-ros/CMakeLists.txt"
if cmake -S "$tmp/bag-needs-ros" -B "$tmp/bag-needs-ros/b" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
  -DCMAKE_DISABLE_FIND_PACKAGE_KfdRos1=TRUE >/dev/null 2>&1; then
  echo "find_package(kfd COMPONENTS bag) succeeded without ROS 1's bag libraries" >&2; exit 1
fi
# A kfd built with the ROS 1 node exports kfd::ros1 (find_package(kfd COMPONENTS ros1)).
if [ -x "$build/apps/kfd_node" ]; then
  [ -x "$tmp/consumer/consumer_ros1" ] || { echo "kfd::ros1 not exported" >&2; exit 1; }
  "$tmp/consumer/consumer_ros1"
fi
# The example reads the bundled log with kfd's defaults, then with a config, and reports a
# missing log and a bad key as the errors they are (exit 1, the key or file named).
cmake -S "$src/examples/filter_log" -B "$tmp/example" -DCMAKE_PREFIX_PATH="$tmp/prefix" >/dev/null
cmake --build "$tmp/example" >/dev/null
log="$src/rawlogs/office-mit-0.752.rawlog"
out="$("$tmp/example/filter_log" "$log")"
echo "$out" | grep -Eq '^600 scans, [1-9][0-9]* kept \([0-9.]+ %\), [0-9]+ points removed' ||
  { echo "example on the bundled log: $out" >&2; exit 1; }
preset="$("$tmp/example/filter_log" "$log" "$src/share/kfd/paper-mit-0.752.ini")"
[ "$preset" != "$out" ] || { echo "example: the paper preset changed nothing: $out" >&2; exit 1; }
if err="$("$tmp/example/filter_log" "$tmp/no-such.rawlog" 2>&1)"; then exit 1; fi
echo "$err" | grep -q '^log: .*no-such.rawlog' || { echo "example, missing log: $err" >&2; exit 1; }
printf '[KFD]\nno_such_key = 1\n' >"$tmp/bad.ini"
if err="$("$tmp/example/filter_log" "$log" "$tmp/bad.ini" 2>&1)"; then exit 1; fi
echo "$err" | grep -q '^config: .*no_such_key' || { echo "example, bad key: $err" >&2; exit 1; }
echo "kfd package found, linked and ran; the example filtered the bundled log: $out"
