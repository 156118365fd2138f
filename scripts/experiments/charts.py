#!/usr/bin/env python3
"""Renders the benchmark chart of docs/RESULTS.md (docs/figures/time-per-stage.png) from
out/bench/stages.json (scripts/bench/bench.sh), with kfd-chart (MRPT's 2D canvas: no display).
The SLAM comparisons draw their own box plots (kfd-compare).
Usage: python3 scripts/experiments/charts.py
"""
import json
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CHART = os.path.join(ROOT, "build", "apps", "kfd-chart")
FIG = os.path.join(ROOT, "docs", "figures")


def chart(rows, out, title, ylabel, log=False):
    with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as f:
        f.write("group,series,value,error\n")
        for r in rows:
            f.write("%s,%s,%.6g,%.6g\n" % r)
    cmd = [CHART, f.name, "-o", os.path.join(FIG, out), "--title", title, "--ylabel", ylabel]
    subprocess.run(cmd + (["--log"] if log else []), check=True)
    os.unlink(f.name)
    print("wrote docs/figures/" + out)


def main():
    os.makedirs(FIG, exist_ok=True)
    bench = os.path.join(ROOT, "out", "bench", "stages.json")  # from scripts/bench/bench.sh
    if os.path.exists(bench):
        names = {"BM_DistanceFilter": "distance", "BM_Histogram": "histogram",
                 "BM_KeyframeDecision": "keyframe decision", "BM_DenoiseReference": "denoise ref",
                 "BM_DenoiseRangeAware": "denoise r-aware", "BM_PipelineDropped": "scan dropped",
                 "BM_PipelineKeyframe/1": "keyframe kept", "BM_Dbscan": "DBSCAN",
                 "BM_RadiusOutlier": "radius", "BM_StatisticalOutlier": "SOR"}
        rows = []
        for b in json.load(open(bench))["benchmarks"]:
            if b.get("aggregate_name") == "median" and b["run_name"] in names:
                us = b["cpu_time"] / (1000.0 if b["time_unit"] == "ns" else 1.0)
                rows.append((names[b["run_name"]], "median CPU time", us, 0))
        chart(rows, "time-per-stage.png",
              "Time per 1081-beam scan by stage (Google Benchmark medians)", "us, log", True)


if __name__ == "__main__":
    main()
