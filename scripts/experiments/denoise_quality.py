#!/usr/bin/env python3
"""Denoising quality on simulated logs with labelled noise (docs/CHANGELOG.md, issue 4 part 3).

Simulates the office world (MIT sensor class, 40 Hz, 1081 beams) at three noise levels, runs
every denoiser on every scan (no keyframe stage) with kfd-denoise-eval, and prints a Markdown
table: precision, recall, F1, true points kept, recall per noise kind, time per scan.
Usage: python3 scripts/experiments/denoise_quality.py [--duration S] [--out DIR]
"""
import argparse
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(ROOT, "build", "apps")
LEVELS = {"low": 0.5, "medium": 1.0, "high": 2.0}  # x the default rates
DEFAULT_RATES = {"isolated": 0.005, "clustered": 0.05, "edge": 0.3}
METHODS = {
    "kfd reference (Algorithm 2)": "pipeline = distance, denoise\nvariant = reference\n",
    "kfd range_aware": "pipeline = distance, denoise\nvariant = range_aware\n",
    "DBSCAN (0.7 m, 10)": "pipeline = distance, dbscan\n",
    "radius outlier removal": "pipeline = distance, radius\n",
    "statistical outlier removal": "pipeline = distance, sor\n",
}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--duration", type=float, default=30.0)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "denoise"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    print("| noise level | method | precision | recall | F1 | true points kept | "
          "recall isolated | recall clustered | recall edge | µs/scan |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for level, f in LEVELS.items():
        log = os.path.join(a.out, "office-%s.rawlog" % level)
        subprocess.run([os.path.join(BIN, "kfd-simulate"), "-o", log, "-d", str(a.duration),
                        "-q", "--isolated", str(DEFAULT_RATES["isolated"] * f),
                        "--clustered", str(min(1.0, DEFAULT_RATES["clustered"] * f)),
                        "--edge", str(min(1.0, DEFAULT_RATES["edge"] * f))],
                       check=True, stdout=subprocess.DEVNULL)
        labels = log[:-len(".rawlog")] + ".labels.csv"
        for name, body in METHODS.items():
            cfg = os.path.join(a.out, "method.ini")
            with open(cfg, "w") as fh:
                fh.write("[KFD]\n" + body)
            r = subprocess.run([os.path.join(BIN, "kfd-denoise-eval"), "-i", log, "-l", labels,
                                "-c", cfg], capture_output=True, text=True)
            if r.returncode != 0:
                print("| %s | %s | not available: %s |||||||| " % (level, name,
                                                                   r.stderr.strip()[:80]))
                continue
            v = {}
            words = r.stdout.split()
            for i, w in enumerate(words[:-1]):
                try:
                    v[w] = float(words[i + 1])
                except ValueError:
                    pass
            print("| %s | %s | %.3f | %.3f | %.3f | %.4f | %.3f | %.3f | %.3f | %.1f |" % (
                level, name, v["precision"], v["recall"], v["f1"], v["clean_kept"],
                v["recall_isolated"], v["recall_clustered"], v["recall_edge"], v["us_per_scan"]))


if __name__ == "__main__":
    main()
