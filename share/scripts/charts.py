#!/usr/bin/env python3
"""Renders the charts of docs/RESULTS.md into docs/figures/ from the experiment outputs
(out/slam/results.json of slam_experiment.py; out/sim-slam/results.json of
sim_slam_experiment.py), with kfd-chart (MRPT's 2D canvas: no display, no extra package).
Usage: python3 share/scripts/charts.py
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
    real = os.path.join(ROOT, "out", "slam", "results.json")
    if os.path.exists(real):
        res = json.load(open(real))
        err, time, drop = [], [], []
        for d, modes in res.items():
            for m, s in modes.items():
                r = s["relations"]
                err.append((d, m, r["trans_mean_m"], r["trans_std_m"]))
                time.append((d, m, s["prefilter_us_per_scan"] / 1000.0 + s["icp_ms_per_scan"], 0))
                drop.append((d, m, s["dropped_pct"], 0))
        chart(err, "relations-error.png",
              "Relations translation error per dataset and mode (mean +- std)", "m, log", True)
        chart(time, "time-per-scan.png",
              "Pre-filter + ICP-SLAM time per input scan", "ms per scan")
        chart(drop, "dropped.png", "Scans dropped by the pre-filter", "% of scans")
    bench = os.path.join(ROOT, "out", "bench", "stages.json")  # from share/scripts/bench.sh
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
    sim = os.path.join(ROOT, "out", "sim-slam", "results.json")
    if os.path.exists(sim):
        res = json.load(open(sim))
        rows = [(t, m, s["ate_rmse"], 0) for t, modes in res.items() for m, s in modes.items()]
        chart(rows, "sim-ate.png", "ATE RMSE on simulated 40 Hz logs", "m, log", True)


if __name__ == "__main__":
    main()
