#!/usr/bin/env bash
# Builds and runs kfd's benchmark suite (test/bench) and prints a Markdown report: medians of
# repeated runs, callgrind instruction counts per scan, kfd-filter's peak memory on logs of
# growing size, and the issue-4 targets (the source of "Benchmarks" in docs/RESULTS.md).
#
# Usage: bash scripts/bench/bench.sh
# Environment:
#   KFD_BENCH_BUILD_DIR   build directory (default: build-bench; RelWithDebInfo)
#   KFD_BENCH_OUT         where JSON, callgrind output and the report go (default: out/bench)
#   KFD_DATASETS_DIR      the Freiburg datasets (default: ../shared/datasets)
#   KFD_BENCH_REPETITIONS repetitions per benchmark (default: 5)
#   KFD_BENCH_CALLS       counted calls per case under callgrind (default: 160)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${KFD_BENCH_BUILD_DIR:-$root/build-bench}"
out="${KFD_BENCH_OUT:-$root/out/bench}"
data="${KFD_DATASETS_DIR:-$root/../shared/datasets}"
reps="${KFD_BENCH_REPETITIONS:-5}"
calls="${KFD_BENCH_CALLS:-160}"

bash "$root/scripts/ci/install-deps.sh"
if ! command -v valgrind >/dev/null; then  # bench-only dependency
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y valgrind
fi

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DKFD_BUILD_BENCHMARKS=ON \
  -DKFD_DATASETS_DIR="$data" >/dev/null
cmake --build "$build" -j"$(nproc)" --target kfd-filter kfd_bench_stages kfd_bench_rawlog \
  kfd_bench_instructions kfd_bench_rawlog_prefix
bench="$build/test/bench"
[ -x "$bench/kfd_bench_stages" ] || { echo "benchmarks not built (libbenchmark-dev?)" >&2; exit 1; }

mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
{
  echo "date: $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores"
  echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "source: $(git -C "$root" describe --always --dirty 2>/dev/null || echo unknown)"
  echo "build: $build (RelWithDebInfo), repetitions: $reps"
} | tee "$out/machine.txt"

# 1. Google Benchmark: per-stage costs and rawlog throughput, repeated; medians in the report.
gbench=(--benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true
  --benchmark_out_format=json)
echo "== kfd_bench_stages" >&2
"$bench/kfd_bench_stages" "${gbench[@]}" --benchmark_out="$out/stages.json"
echo "== kfd_bench_rawlog" >&2
KFD_DATASETS_DIR="$data" "$bench/kfd_bench_rawlog" "${gbench[@]}" --benchmark_out="$out/rawlog.json"

# 2. Instructions per scan (callgrind: deterministic, unlike time on a shared machine).
echo "== callgrind ($calls calls per case)" >&2
valgrind --tool=callgrind --callgrind-out-file="$out/callgrind.out" \
  "$bench/kfd_bench_instructions" "$calls" >/dev/null 2>"$tmp/valgrind.log" ||
  { cat "$tmp/valgrind.log" >&2; exit 1; }
callgrind_annotate --inclusive=yes --auto=no --threshold=100 "$out/callgrind.out" |
  grep 'kfd_ir_' >"$out/callgrind.txt"

# 3. kfd-filter's peak memory (max RSS) on logs of growing size: the first 25 / 50 / 100 % of
#    mit-killian's objects, then the five datasets. Built-in defaults, as BM_FilterRawlog/0.
echo "== peak memory" >&2
: >"$out/memory.tsv"
measure() {  # name, input
  local name="$1" in="$2"
  /usr/bin/time -v "$build/apps/kfd-filter" -q -i "$in" -o "$tmp/filtered.rawlog" \
    >"$tmp/filter.txt" 2>"$tmp/time.txt"
  local rss wall scans size
  rss="$(awk -F': ' '/Maximum resident set size/ {print $2}' "$tmp/time.txt")"
  wall="$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$tmp/time.txt")"
  scans="$(awk '/^  scans/ {gsub(/,/, ""); print $3}' "$tmp/filter.txt")"
  size="$(stat -c %s "$in")"
  printf '%s\t%s\t%s\t%s\t%s\n' "$name" "$scans" "$size" "$rss" "$wall" >>"$out/memory.tsv"
}
killian="$data/mit-killian/mit-killian.rawlog"
if [ -f "$killian" ]; then
  for pct in 25 50; do
    "$bench/kfd_bench_rawlog_prefix" "$killian" "$tmp/killian-$pct.rawlog" "$pct" >/dev/null
    measure "mit-killian first $pct %" "$tmp/killian-$pct.rawlog"
  done
  measure "mit-killian 100 %" "$killian"
fi
for d in mit-csail aces fr079 intel; do
  if [ -f "$data/$d/$d.rawlog" ]; then measure "$d" "$data/$d/$d.rawlog"; fi
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$out/machine.txt"

# 4. Report.
python3 - "$out" "$calls" <<'PY' | tee "$out/report.md"
import json, re, sys
out, calls = sys.argv[1], int(sys.argv[2])

def medians(path):
    try:
        runs = json.load(open(path))["benchmarks"]
    except (OSError, ValueError):
        return {}
    res = {}
    for b in runs:
        if b.get("error_occurred"):
            res[b["run_name"]] = {"error": b.get("error_message", "error")}
        elif b.get("aggregate_name") == "median":
            res[b["run_name"]] = b
    return res

def us(b, key="cpu_time"):
    scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}[b["time_unit"]]
    return b[key] * scale

st = medians(f"{out}/stages.json")
rl = medians(f"{out}/rawlog.json")

print("### Per-scan cost (1081 beams, 270 deg; medians)\n")
rows = [
    ("BM_RestoreValid", "restore valid flags (harness overhead, included below where marked *)"),
    ("BM_DistanceFilter", "distance filter (Algorithm 1) *"),
    ("BM_Histogram", "histogram, n = 20"),
    ("BM_Pearson", "one Pearson correlation, n = 20"),
    ("BM_KeyframeDecision", "keyframe decision, m = 8 (histogram + 8 correlations), dropped scan"),
    ("BM_KeyframeView/0", "keyframe decision, view selector (kfd's default), odometry, dropped scan"),
    ("BM_KeyframeView/1", "keyframe decision, view selector, laser only, dropped scan"),
    ("BM_Tracker", "scan tracker (issue 35), dropped scan against its keyframe"),
    ("BM_IcpMrpt", "MRPT ICP, every-scan config's [ICP], scan vs local map (no insertion)"),
    ("BM_DenoiseReference", "denoise, reference (rings + filter) *"),
    ("BM_DenoiseRangeAware", "denoise, range-aware *"),
    ("BM_DenoiseEvidence", "denoise, evidence (kfd's default), loop keyframes *"),
    ("BM_DbscanLoop", "DBSCAN, Eps 0.7 m, minPts 10, loop keyframes *"),
    ("BM_PipelineDropped", "Pipeline::process, keyframe dropped *"),
    ("BM_PipelineKeyframe/0", "Pipeline::process, keyframe kept, reference *"),
    ("BM_PipelineKeyframe/1", "Pipeline::process, keyframe kept, range-aware *"),
    ("BM_Dbscan", "DBSCAN, Eps 0.7 m, minPts 10 *"),
    ("BM_RadiusOutlier", "radius outlier removal (0.3 m, 3 neighbours) *"),
    ("BM_StatisticalOutlier", "statistical outlier removal (k = 8, 1 sigma) *"),
]
print("| benchmark | what | CPU (us/scan) | wall (us/scan) | points removed per scan |")
print("|---|---|---:|---:|---:|")
for name, what in rows:
    b = st.get(name)
    if not b:
        print(f"| {name} | {what} | not run | | |")
    elif "error" in b:
        print(f"| {name} | {what} | skipped: {b['error']} | | |")
    else:
        rem = b.get("removed")
        rem = "" if rem is None else f"{rem:.1f}"
        print(f"| {name} | {what} | {us(b):.3f} | {us(b, 'real_time'):.3f} | {rem} |")

print("\n### Instructions per scan (callgrind, %d calls per case)\n" % calls)
ir = {}
for line in open(f"{out}/callgrind.txt"):
    m = re.match(r"\s*([\d,]+)\s.*:kfd_ir_(\w+)", line)
    if m:
        # A function whose inlined code comes from several files is listed once per file, each
        # line with (about) its whole inclusive cost: the largest is the function's.
        ir[m.group(2)] = max(ir.get(m.group(2), 0), int(m.group(1).replace(",", "")))
print("| call | instructions per scan |")
print("|---|---:|")
for name, total in sorted(ir.items(), key=lambda kv: kv[1]):
    print(f"| {name} | {total / calls:,.0f} |")

print("\n### kfd-filter on mit-killian (17480 scans) against the I/O limit (medians, wall time)\n")
print("| benchmark | what | median (ms) | x parse |")
print("|---|---|---:|---:|")
parse = rl.get("BM_ParseRawlog/real_time")
base = us(parse, "real_time") if parse and "error" not in parse else None
for name, what in [
    ("BM_ParseRawlog/real_time", "read every object, nothing else"),
    ("BM_CopyRawlog/real_time", "read every object and write it (gzip 1)"),
    ("BM_FilterRawlog/0/real_time", "RawlogFilter::run (kfd-filter), kfd's defaults"),
    ("BM_FilterRawlog/1/real_time", "RawlogFilter::run (kfd-filter), paper-mit-0.752.ini"),
    ("BM_FilterRawlog/2/real_time", "RawlogFilter::run, kfd's defaults, --compress 0"),
]:
    b = rl.get(name)
    if not b:
        print(f"| {name} | {what} | not run | |")
    elif "error" in b:
        print(f"| {name} | {what} | skipped: {b['error']} | |")
    else:
        t = us(b, "real_time")
        print(f"| {name} | {what} | {t / 1e3:.1f} | {t / base:.2f} |" if base else
              f"| {name} | {what} | {t / 1e3:.1f} | |")

print("\n### kfd-filter peak memory (kfd's defaults, no -c)\n")
mem = [l.rstrip("\n").split("\t") for l in open(f"{out}/memory.tsv") if l.strip()]
print("| input | scans | file (MB) | max RSS (MB) | wall (m:ss) |")
print("|---|---:|---:|---:|---:|")
for name, scans, size, rss, wall in mem:
    print(f"| {name} | {scans} | {int(size) / 1e6:.1f} | {int(rss) / 1024:.1f} | {wall} |")

def verdict(ok):
    return "**met**" if ok else "**missed**"

print("\n### Targets\n")
print("| target | measured | result |")
print("|---|---|---|")
kd = st.get("BM_KeyframeDecision")
if kd and "error" not in kd:
    print(f"| keyframe decision <= 5 us per 1081-beam scan | {us(kd):.2f} us | {verdict(us(kd) <= 5)} |")
db = st.get("BM_Dbscan")
for key, ir_key, label in [("BM_DenoiseReference", "denoise_reference", "reference"),
                           ("BM_DenoiseRangeAware", "denoise_range_aware", "range-aware")]:
    d = st.get(key)
    if d and "error" not in d:
        print(f"| denoising a keyframe <= 20 us ({label}) | {us(d):.1f} us | {verdict(us(d) <= 20)} |")
        if db and "error" not in db:
            r = us(db) / us(d)
            ir_ratio = ""
            if ir.get("dbscan") and ir.get(ir_key):
                ir_ratio = f"; instructions {ir['dbscan'] / ir[ir_key]:.0f}x"
            print(f"| >= 50x faster than DBSCAN ({label}) | DBSCAN {us(db):.0f} us, {r:.0f}x{ir_ratio} | {verdict(r >= 50)} |")
for key, label in [("BM_KeyframeView/0", "view selector, odometry"),
                   ("BM_KeyframeView/1", "view selector, laser only")]:
    b = st.get(key)
    if b and "error" not in b:
        print(f"| keyframe decision about 2 us per 1081-beam scan ({label}) | {us(b):.2f} us | {verdict(us(b) <= 2)} |")
# Issue 12: the keyframe decision of kfd's default selector (view), with and without odometry,
# and the paper's histogram + correlation decision, per 1081-beam scan.
for key, label in [("keyframe_view", "view selector, odometry"),
                   ("keyframe_view_laser_only", "view selector, laser only"),
                   ("keyframe_decision", "paper's rule (histogram, m = 8)")]:
    if ir.get(key):
        n = ir[key] / calls
        print(f"| keyframe decision <= 10 000 instructions per 1081-beam scan ({label}) | {n:,.0f} | {verdict(n <= 10000)} |")
# Issue 20: a dropped 1081-beam scan through kfd's default pipeline (distance, view keyframe,
# denoise) <= 15 000 instructions, with the keyframe decision <= 10 000 of it; and the same scan
# through the one door (StreamFilter::process: the check and the MRPT adapter added).
if ir.get("pipeline_dropped_view"):
    n = ir["pipeline_dropped_view"] / calls
    parts = ", ".join(f"{label} {ir[k] / calls:,.0f}" for k, label in
                      [("distance_filter", "distance filter"), ("keyframe_view", "keyframe decision")]
                      if ir.get(k))
    print(f"| dropped scan through the pipeline <= 15 000 instructions (kfd's default; {parts}) | {n:,.0f} | {verdict(n <= 15000)} |")
if ir.get("door_dropped_view"):
    print(f"| dropped scan through the door (StreamFilter::process, MRPT scan), reported | {ir['door_dropped_view'] / calls:,.0f} | reported |")
# Issue 35: the scan tracker per dropped scan beside MRPT's ICP per scan (CPU, same run of
# kfd_bench_stages: valgrind cannot run mrpt-slam's libraries), and the dropped scan through
# kfd's default pipeline since issue 35 (odometry check, distance, track, view keyframe,
# evidence denoise) <= 40 000 instructions.
tr, icp = st.get("BM_Tracker"), st.get("BM_IcpMrpt")
if tr and icp and "error" not in tr and "error" not in icp:
    trn = f", {ir['tracker'] / calls:,.0f} instructions" if ir.get("tracker") else ""
    print(f"| scan tracker beside MRPT ICP per scan (CPU, same run), reported | tracker {us(tr):.1f} us{trn}; ICP {us(icp):.0f} us, {us(icp) / us(tr):.0f}x the tracker | reported |")
if ir.get("pipeline_dropped_track"):
    n = ir["pipeline_dropped_track"] / calls
    tn = f"; tracker {ir['tracker'] / calls:,.0f}" if ir.get("tracker") else ""
    print(f"| dropped scan through kfd's default pipeline with the tracker <= 40 000 instructions{tn} | {n:,.0f} | {verdict(n <= 40000)} |")
# Issue 11: the evidence denoiser, on the loop keyframes (its temporal evidence needs the
# previous keyframe), against DBSCAN on the same scans and in the same run.
ev, dbl = st.get("BM_DenoiseEvidence"), st.get("BM_DbscanLoop")
if ir.get("denoise_evidence"):
    n = ir["denoise_evidence"] / calls
    print(f"| evidence denoise <= 200 000 instructions per 1081-beam scan | {n:,.0f} | {verdict(n <= 200000)} |")
if ev and dbl and "error" not in ev and "error" not in dbl:
    r = us(dbl) / us(ev)
    ir_ratio = ""
    if ir.get("dbscan_loop") and ir.get("denoise_evidence"):
        ir_ratio = f"; instructions {ir['dbscan_loop'] / ir['denoise_evidence']:.0f}x"
    print(f"| evidence >= 80x faster than DBSCAN (same scans, same run) | evidence {us(ev):.1f} us, DBSCAN {us(dbl):.0f} us, {r:.0f}x{ir_ratio} | {verdict(r >= 80)} |")
f0 = rl.get("BM_FilterRawlog/0/real_time")
cp = rl.get("BM_CopyRawlog/real_time")
if base and f0 and "error" not in f0:
    r = us(f0, "real_time") / base
    extra = ""
    if cp and "error" not in cp:
        extra = f"; {us(f0, 'real_time') / us(cp, 'real_time'):.2f}x of read + write"
    print(f"| kfd-filter within 1.5x of plain parse | {r:.2f}x{extra} | {verdict(r <= 1.5)} |")
if len(mem) >= 3 and mem[0][0].startswith("mit-killian"):
    rss = [int(m[3]) for m in mem[:3]]
    growth = rss[2] / rss[0] - 1
    print(f"| peak memory flat as the log grows (100 % vs 25 % of mit-killian, <= 5 %) | "
          f"{rss[0] / 1024:.1f} -> {rss[2] / 1024:.1f} MB ({100 * growth:+.1f} %) | {verdict(growth <= 0.05)} |")
PY
