#!/usr/bin/env python3
"""Runs kfd-icp-slam in every pre-filter mode on the five Freiburg benchmark logs and prints
the Markdown tables of docs/RESULTS.md ("ICP-SLAM with the pre-filter").

Usage: python3 share/scripts/slam_experiment.py [--datasets DIR] [--config INI] [--out DIR]
                                                 [--only NAME ...] [--modes MODE ...]
Modes: every mode of `kfd-icp-slam --list-modes` (or those of --modes), kfd first (its drop
rate is the target for the odometry baseline, run with --match-drop <kfd's drop %>). Every mode
uses the same
ICP-SLAM config and the same [KFD] section; nothing is tuned per dataset.
"""
import argparse
import json
import os
import subprocess
import sys

from kfd_modes import choose

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATASETS = ["mit-csail", "intel", "aces", "fr079", "mit-killian"]
# Kuemmerle et al. 2009, Table 1, scan matching, translation error (m): mean +- std.
KUEMMERLE = {"aces": (0.173, 0.614), "intel": (0.220, 0.296), "mit-killian": (1.651, 4.138),
             "mit-csail": (0.106, 0.325), "fr079": (0.258, 0.427)}
MAX_DT = {"mit-killian": 0.22}  # estimated stamps, see its PROVENANCE.md


def run(exe, cfg, rawlog, rel, out, mode, extra):
    cmd = [exe, cfg, rawlog, "-o", out, "-m", mode, "-q", "--no-map", "-g", rel,
           "--max-dt", str(extra.get("max_dt", 0.001))]
    if "match_drop" in extra:
        cmd += ["--match-drop", "%.4f" % extra["match_drop"]]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--datasets", default=os.path.join(ROOT, "..", "shared", "datasets"))
    ap.add_argument("--config", default=os.path.join(ROOT, "share", "kfd-icp-slam",
                                                     "sick-180-5hz.ini"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "slam"))
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "apps", "kfd-icp-slam"))
    ap.add_argument("--only", nargs="*", default=DATASETS)
    ap.add_argument("--modes", nargs="*", help="default: every mode of kfd-icp-slam --list-modes")
    a = ap.parse_args()
    if not os.access(a.exe, os.X_OK):
        sys.exit("build kfd-icp-slam first (bash share/scripts/demo.sh)")
    modes = choose(a.exe, a.modes)
    results = {}
    for d in a.only:
        rawlog = os.path.join(a.datasets, d, d + ".rawlog")
        rel = os.path.join(a.datasets, d, d + ".relations")
        if not os.path.exists(rawlog):
            print("missing: " + rawlog, file=sys.stderr)
            continue
        results[d] = {}
        for mode in modes:
            extra = {"max_dt": MAX_DT.get(d, 0.001)}
            if mode == "odometry":
                extra["match_drop"] = results[d]["kfd"]["dropped_pct"]
            print("[slam-experiment] %s %s" % (d, mode), file=sys.stderr, flush=True)
            results[d][mode] = run(a.exe, a.config, rawlog, rel, os.path.join(a.out, d, mode),
                                   mode, extra)
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(results, f, indent=1)

    print("| dataset | mode | dropped | relations trans (m) | relations rot (deg) | "
          "pre-filter (us/scan) | ICP-SLAM (ms/scan) | CPU total (s) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for d, per_mode in results.items():
        for mode in modes:
            s = per_mode[mode]
            r = s["relations"]
            note = " (%d unmatched)" % r["unmatched"] if r["unmatched"] else ""
            print("| %s | %s | %.1f %% | %.3f ± %.3f%s | %.2f ± %.2f | %.1f | %.3f | %.2f |" % (
                d + (" ¹" if d == "mit-killian" else ""), mode, s["dropped_pct"],
                r["trans_mean_m"], r["trans_std_m"], note, r["rot_mean_deg"], r["rot_std_deg"],
                s["prefilter_us_per_scan"], s["icp_ms_per_scan"], s["cpu_s_total"]))
        k = KUEMMERLE[d]
        print("| %s | *Kümmerle 2009, scan matching* | | *%.3f ± %.3f* | | | | |" % (d, k[0], k[1]))


if __name__ == "__main__":
    main()
    # Render the charts of docs/RESULTS.md from the results just written.
    subprocess.run([sys.executable, os.path.join(ROOT, "share", "scripts", "charts.py")],
                   check=True, stdout=sys.stderr)
