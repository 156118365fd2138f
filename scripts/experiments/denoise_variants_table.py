#!/usr/bin/env python3
"""Markdown tables of scripts/experiments/denoise-variants.sh's results (issue 25): per log and variant the
recall of each noise kind, precision and the real returns kept, then recall per noise model.
Usage: python3 scripts/experiments/denoise_variants_table.py out/denoise-variants/seed11 NAME ..."""
import pathlib
import re
import sys


def read(path):
    text = path.read_text()
    out = {}
    m = re.search(r"scored (\d+) kept of (\d+)", text)
    if m:
        out["scored"], out["scans"] = int(m.group(1)), int(m.group(2))
    for key, val in re.findall(r"(\w+) ([0-9.]+)", text):
        out.setdefault(key, val)
    return out


def main():
    d = pathlib.Path(sys.argv[1])
    ns = sys.argv[2:]
    logs = ["fr079", "aces", "intel", "mit-csail", "mines-exp1", "mines-exp2"]
    models = None
    print("| log | variant | scored (kept of all) | isolated | clustered | mixed (edge) | all | precision | real kept (noisy) | real kept (clean) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    per_model = []
    for log in logs:
        for n in ns:
            noisy, clean = d / f"{log}-{n}-noisy.txt", d / f"{log}-{n}-clean.txt"
            if not noisy.exists() or not clean.exists():
                continue
            a, c = read(noisy), read(clean)
            print(f"| {log} | {n} | {a['scored']} of {a['scans']} | {a['recall_isolated']} | "
                  f"{a['recall_clustered']} | {a['recall_edge']} | {a['recall']} | "
                  f"{a['precision']} | {a['clean_kept']} | {c['clean_kept']} |")
            ms = re.findall(r"recall_(\w+) ([0-9.]+) \((\d+)\)", noisy.read_text())
            models = models or [m for m, _, _ in ms]
            per_model.append((log, n, {m: v for m, v, _ in ms}))
    if models:
        print()
        print("| log | variant | " + " | ".join(models) + " |")
        print("|---|---|" + "---|" * len(models))
        for log, n, vals in per_model:
            print(f"| {log} | {n} | " + " | ".join(vals.get(m, "-") for m in models) + " |")


if __name__ == "__main__":
    main()
