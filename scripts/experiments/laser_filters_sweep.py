#!/usr/bin/env python3
"""Issue 39's criterion over denoise-vs-laser-filters.sh's results (run with SWEEP=1): per log,
kfd's default against every laser_filters-equivalent configuration that keeps at least as many
real returns of the clean log as kfd does; a configuration that also finds more of a noise kind
(isolated, bursts, mixed pixels) than kfd is a miss, and is listed.
Usage: python3 scripts/experiments/laser_filters_sweep.py out/denoise-vs-laser-filters/seedSEED"""
import pathlib
import re
import sys

KINDS = (("isolated", "recall_isolated"), ("bursts", "recall_clustered"),
         ("mixed", "recall_edge"))
LOGS = ("fr079", "aces", "intel", "mit-csail", "mines-exp1", "mines-exp2")
KFD = ("default", "before", "tracked", "veil", "reference")


def scores(d, log, name):
    """Recall per kind (noisy log) and real kept (clean log) of one configuration, or None."""
    noisy, clean = d / f"{log}-{name}-noisy.txt", d / f"{log}-{name}-clean.txt"
    if not noisy.exists() or not clean.exists():
        return None
    a = dict(re.findall(r"(\w+) ([0-9.]+)", noisy.read_text()))
    c = dict(re.findall(r"(\w+) ([0-9.]+)", clean.read_text()))
    out = {k: float(a[key]) for k, key in KINDS}
    out["kept"] = float(c["clean_kept"])
    return out


def names(d, log):
    return sorted({p.name[len(log) + 1:-len("-noisy.txt")] for p in d.glob(f"{log}-*-noisy.txt")}
                  - set(KFD))


def row(name, s):
    return "| %s | %.3f | %.3f | %.3f | %.4f |" % (
        name, s["isolated"], s["bursts"], s["mixed"], s["kept"])


def main():
    d = pathlib.Path(sys.argv[1])
    misses = 0
    for log in LOGS:
        kfd = scores(d, log, "default")
        if kfd is None:
            continue
        base = {n: s for n in names(d, log) if (s := scores(d, log, n)) is not None}
        eligible = {n: s for n, s in base.items() if s["kept"] >= kfd["kept"]}
        print("## %s: %d configurations, %d keep as many real returns as kfd\n"
              % (log, len(base), len(eligible)))
        print("| configuration | isolated | bursts | mixed | real kept |")
        print("|---|---:|---:|---:|---:|")
        print(row("**kfd default**", kfd))
        for kind, _ in KINDS:  # the best of each kind, among those keeping as much, then any
            for pool, tag in ((eligible, "best %s, real kept >= kfd" % kind),
                              (base, "best %s, any real kept" % kind)):
                if pool:
                    n = max(pool, key=lambda m: (pool[m][kind], pool[m]["kept"]))
                    print(row("%s (%s)" % (n, tag), pool[n]))
        beaten = [(n, k) for n, s in sorted(eligible.items()) for k, _ in KINDS if s[k] > kfd[k]]
        misses += len(beaten)
        print("\n" + ("Missed: " + ", ".join("%s finds more %s" % b for b in beaten)
                      if beaten else "Met: no such configuration finds more of any kind.") + "\n")
    return 0 if misses == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
