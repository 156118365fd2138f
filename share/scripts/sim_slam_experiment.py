#!/usr/bin/env python3
"""The 40 Hz experiment (docs/RESULTS.md, issue 4 part 5): kfd-icp-slam in every mode on
simulated 40 Hz logs (office at the paper's two speeds, and the long corridor), ATE RMSE against
the simulated ground truth, dropped %, CPU time.

Usage: python3 share/scripts/sim_slam_experiment.py [--out DIR]
The [KFD] section is the paper's setting for each speed (0.752 m/s: m=8, n=20, P_pair=0.985;
0.575 m/s: m=9, n=15, P_pair=0.99), both inside the range Formulas 4-5 allow, plus kfd's guards
and range-aware clustering (share/kfd/kfd-40hz.ini). The ICP-SLAM part is
share/kfd-icp-slam/sick-180-5hz.ini unchanged.
"""
import argparse
import json
import os
import re
import subprocess
import sys

from kfd_modes import choose

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(ROOT, "build", "apps")
RUNS = [("office", 0.752), ("office", 0.575), ("corridor", 0.752)]
PAPER = {0.752: (8, 20, 0.985), 0.575: (9, 15, 0.99)}


def config(out, speed):
    icp = open(os.path.join(ROOT, "share", "kfd-icp-slam", "sick-180-5hz.ini")).read()
    icp = icp[:icp.index("\n[KFD]") + 1]  # the ICP-SLAM part, without its [KFD] section
    kfd = open(os.path.join(ROOT, "share", "kfd", "kfd-40hz.ini")).read()
    m, n, p = PAPER[speed]
    kfd = re.sub(r"(?m)^window = .*$", "window = %d" % m, kfd)
    kfd = re.sub(r"(?m)^bins = .*$", "bins = %d" % n, kfd)
    kfd = re.sub(r"(?m)^p_pair = .*$", "p_pair = %g" % p, kfd)
    path = os.path.join(out, "icp-40hz-%g.ini" % speed)
    with open(path, "w") as f:
        f.write(icp + kfd)
    return path


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "sim-slam"))
    ap.add_argument("--modes", nargs="*", help="default: every mode of kfd-icp-slam --list-modes")
    a = ap.parse_args()
    modes = choose(os.path.join(BIN, "kfd-icp-slam"), a.modes)
    os.makedirs(a.out, exist_ok=True)
    results = {}
    print("| log | mode | dropped | ATE RMSE (m) | ATE max (m) | pre-filter (µs/scan) | "
          "ICP-SLAM (ms/scan) | CPU total (s) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for world, speed in RUNS:
        tag = "%s-%g" % (world, speed)
        log = os.path.join(a.out, tag + ".rawlog")
        subprocess.run([os.path.join(BIN, "kfd-simulate"), "-o", log, "-w", world, "-v",
                        str(speed), "-q"], check=True, stdout=subprocess.DEVNULL)
        gt = log[:-len(".rawlog")] + ".gt.tum"
        cfg = config(a.out, speed)
        res = {}
        odo = subprocess.run([os.path.join(BIN, "kfd-eval"), log[:-len(".rawlog")] + ".odom.tum",
                              "--gt", gt], capture_output=True, text=True, check=True).stdout
        for mode in modes:
            out = os.path.join(a.out, tag, mode)
            cmd = [os.path.join(BIN, "kfd-icp-slam"), cfg, log, "-o", out, "-m", mode, "-q",
                   "--no-map"]
            if mode == "odometry":
                cmd += ["--match-drop", "%.4f" % res["kfd"]["dropped_pct"]]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            s = json.load(open(os.path.join(out, "summary.json")))
            ev = subprocess.run([os.path.join(BIN, "kfd-eval"), os.path.join(out, "trajectory.tum"),
                                 "--gt", gt], capture_output=True, text=True, check=True).stdout
            mt = re.search(r"RMSE ([0-9.]+) m, mean ([0-9.]+) m, max ([0-9.]+) m", ev)
            s["ate_rmse"], s["ate_max"] = float(mt.group(1)), float(mt.group(3))
            res[mode] = s
            print("| %s | %s | %.1f %% | %.3f | %.3f | %.1f | %.3f | %.2f |" % (
                tag, mode, s["dropped_pct"], s["ate_rmse"], s["ate_max"],
                s["prefilter_us_per_scan"], s["icp_ms_per_scan"], s["cpu_s_total"]), flush=True)
        mo = re.search(r"RMSE ([0-9.]+) m", odo)
        print("| %s | *odometry only* | | %s | | | | |" % (tag, mo.group(1)), flush=True)
        results[tag] = res
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
    # Render the charts of docs/RESULTS.md from the results just written.
    subprocess.run([sys.executable, os.path.join(ROOT, "share", "scripts", "charts.py")],
                   check=True, stdout=sys.stderr)
