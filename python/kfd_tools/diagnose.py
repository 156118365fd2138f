"""kfd-compare diagnose: where a mode's dropped scans cost accuracy, against another mode.

For every log and config of a kfd-compare output folder, and for each of the modes given, over
all repeats: the motion between consecutive kept scans (the gaps, measured on the `reference`
mode's trajectory of repeat 0, ICP on every scan: locally the best motion estimate the runs
have), the share of drops taken while stationary (< 5 mm and < 0.3 deg since the previous scan),
and the local relations error (relations within --split-seconds) grouped by the largest gap the
relation spans. Reads each run's scans.csv and trajectory.tum and the log's .relations.
"""
import bisect
import csv
import json
import math
import os

from .stats import median, quantile

STATIONARY_M, STATIONARY_DEG = 0.005, 0.3
TRANS_BINS = [(0.0, 0.15), (0.15, 0.3), (0.3, float("inf"))]
ROT_BINS = [(0.0, 3.0), (3.0, 8.0), (8.0, float("inf"))]


def read_tum(path):
    poses = []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            a = line.split()
            poses.append((float(a[0]), float(a[1]), float(a[2]),
                          2.0 * math.atan2(float(a[6]), float(a[7]))))
    poses.sort()
    return poses


def read_scans(path):
    with open(path) as f:
        return [(float(r["timestamp"]), r["kept"] == "1") for r in csv.DictReader(f)]


def read_relations(path):
    rel = []
    with open(path) as f:
        for line in f:
            a = line.split()
            if len(a) >= 8:
                rel.append((float(a[0]), float(a[1]), float(a[2]), float(a[3])))
    return rel


def wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def between(a, b):
    dx, dy = b[1] - a[1], b[2] - a[2]
    c, s = math.cos(a[3]), math.sin(a[3])
    return (c * dx + s * dy, -s * dx + c * dy, wrap(b[3] - a[3]))


class Nearest:
    def __init__(self, poses, max_dt):
        self.poses, self.t, self.max_dt = poses, [p[0] for p in poses], max_dt

    def __call__(self, t):
        i = bisect.bisect_left(self.t, t)
        best = None
        for j in (i - 1, i):
            if 0 <= j < len(self.t) and abs(self.t[j] - t) <= self.max_dt:
                if best is None or abs(self.t[j] - t) < abs(best[0] - t):
                    best = self.poses[j]
        return best


def diagnose_mode(runs_dir, mode, ref, relations, split_s, max_dt):
    gaps_t, gaps_r, drops, still = [], [], 0, 0
    by_bin = {}
    repeats = sorted(d for d in os.listdir(os.path.join(runs_dir, mode)) if d.startswith("r"))
    for rep in repeats:
        d = os.path.join(runs_dir, mode, rep)
        if not os.path.isfile(os.path.join(d, "scans.csv")):
            continue
        scans = read_scans(os.path.join(d, "scans.csv"))
        est = Nearest(read_tum(os.path.join(d, "trajectory.tum")), max_dt)
        gaps, last, prev = [], None, None
        for t, kept in scans:
            p = ref(t)
            if p is None:
                continue
            if prev is not None and not kept:
                b = between(prev, p)
                drops += 1
                still += math.hypot(b[0], b[1]) < STATIONARY_M and \
                    abs(math.degrees(b[2])) < STATIONARY_DEG
            prev = p
            if kept:
                if last is not None:
                    b = between(last[1], p)
                    gaps.append((last[0], t, math.hypot(b[0], b[1]), abs(math.degrees(b[2]))))
                last = (t, p)
        gaps_t += [g[2] for g in gaps]
        gaps_r += [g[3] for g in gaps]
        starts = [g[0] for g in gaps]
        for t1, t2, x, y in relations:
            if t2 - t1 > split_s:
                continue
            a, b = est(t1), est(t2)
            if a is None or b is None:
                continue
            e = between(a, b)
            err = math.hypot(e[0] - x, e[1] - y)
            i = max(bisect.bisect_right(starts, t1) - 1, 0)
            j = bisect.bisect_left(starts, t2)
            span = gaps[i:j + 1]
            mt = max([g[2] for g in span] or [0.0])
            mr = max([g[3] for g in span] or [0.0])
            for lo, hi in TRANS_BINS:
                if lo <= mt < hi:
                    by_bin.setdefault(("trans", lo), []).append(err)
            for lo, hi in ROT_BINS:
                if lo <= mr < hi:
                    by_bin.setdefault(("rot", lo), []).append(err)
    return {"repeats": len(repeats), "gaps_t": gaps_t, "gaps_r": gaps_r, "drops": drops,
            "still": still, "by_bin": by_bin}


def diagnose(out, modes, reference="none", split_s=10.0, datasets=None, max_dt=1e-3):
    """Markdown for every log/config of `out` that has all of `modes` and `reference`."""
    lines = ["# kfd-compare diagnose: %s (motion from `%s`, repeat 0)\n" %
             (" vs ".join(modes), reference)]
    runs = os.path.join(out, "runs")
    for log in sorted(os.listdir(runs)):
        for config in sorted(os.listdir(os.path.join(runs, log))):
            base = os.path.join(runs, log, config)
            if not all(os.path.isdir(os.path.join(base, m)) for m in modes + [reference]):
                continue
            run0 = os.path.join(base, reference, "r00")
            meta = {}
            if os.path.isfile(os.path.join(run0, "run.json")):
                with open(os.path.join(run0, "run.json")) as f:
                    meta = json.load(f)
            rel_path = None
            cmd = meta.get("command", [])
            if "-g" in cmd:
                rel_path = cmd[cmd.index("-g") + 1]
            elif datasets:
                cand = os.path.join(datasets, log, log + ".relations")
                rel_path = cand if os.path.isfile(cand) else None
            relations = read_relations(rel_path) if rel_path else []
            ref = Nearest(read_tum(os.path.join(run0, "trajectory.tum")), max_dt)
            lines.append("## %s, %s\n" % (log, config))
            lines.append("| mode | runs | gap m median / p95 / p99 / max | gap deg median / p95 / "
                         "p99 / max | drops while stationary |")
            lines.append("|---|---:|---|---|---:|")
            res = {m: diagnose_mode(base, m, ref, relations, split_s, max_dt) for m in modes}
            for m in modes:
                r = res[m]
                gt, gr = r["gaps_t"], r["gaps_r"]
                lines.append("| %s | %d | %.3f / %.3f / %.3f / %.2f | %.2f / %.2f / %.2f / %.1f | "
                             "%.1f %% |" % (m, r["repeats"], quantile(gt, .5), quantile(gt, .95),
                                            quantile(gt, .99), max(gt or [0]), quantile(gr, .5),
                                            quantile(gr, .95), quantile(gr, .99), max(gr or [0]),
                                            100.0 * r["still"] / max(r["drops"], 1)))
            if relations:
                lines.append("\nLocal relations error (m), median [n], by the largest gap inside "
                             "the relation:\n")
                head = ["%s %g-%g m" % ("trans", lo, hi) for lo, hi in TRANS_BINS] + \
                    ["%s %g-%g deg" % ("rot", lo, hi) for lo, hi in ROT_BINS]
                lines.append("| mode | " + " | ".join(h.replace("-inf", "+") for h in head) + " |")
                lines.append("|---|" + "---:|" * len(head))
                for m in modes:
                    cells = []
                    for kind, bins in (("trans", TRANS_BINS), ("rot", ROT_BINS)):
                        for lo, _ in bins:
                            v = res[m]["by_bin"].get((kind, lo), [])
                            cells.append("%.3f [%d]" % (median(v), len(v)) if v else "–")
                    lines.append("| %s | %s |" % (m, " | ".join(cells)))
            lines.append("")
    return "\n".join(lines) + "\n"
