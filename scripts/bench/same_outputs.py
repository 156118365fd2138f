#!/usr/bin/env python3
"""Compares two runs' per-scan CSVs or summary.json files by name (same-results.sh's helper).

  same_outputs.py csv OLD NEW [SKIP...]   every column both headers name agrees, row by row
                                          (but the SKIP columns); a column only OLD has must
                                          hold one value throughout (a stage that did not run:
                                          issue 34 writes the listed stages' columns only)
  same_outputs.py json OLD NEW REGEX      every key both name agrees (but keys matching REGEX);
                                          a key only OLD has must be 0 (a counter of a stage
                                          not listed); a key only NEW has is an addition
Exits 1 and prints the first difference when they disagree.
"""
import csv
import json
import re
import sys


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def same_csv(old_path, new_path, skip):
    old, new = rows(old_path), rows(new_path)
    if len(old) != len(new):
        return f"{len(old)} rows vs {len(new)}"
    if not old:
        return None
    both = [c for c in old[0] if c in new[0] and c not in skip]
    for c in (c for c in old[0] if c not in new[0]):
        if len({r[c] for r in old}) > 1:
            return f"column {c} gone but it varied"
    for i, (a, b) in enumerate(zip(old, new)):
        for c in both:
            if a[c] != b[c]:
                return f"row {i + 1}, {c}: {a[c]} vs {b[c]}"
    return None


def same_json(old_path, new_path, skip):
    with open(old_path) as f:
        old = json.load(f)
    with open(new_path) as f:
        new = json.load(f)
    for k in sorted(set(old) | set(new)):
        if re.search(skip, f'"{k}"'):
            continue
        if k not in old:
            continue  # added
        if k not in new:
            if old[k] not in (0, 0.0):
                return f"{k} gone, but it was {old[k]}"
        elif old[k] != new[k]:
            return f"{k}: {old[k]} vs {new[k]}"
    return None


def main(argv):
    if len(argv) < 4 or argv[1] not in ("csv", "json"):
        print(__doc__, file=sys.stderr)
        return 2
    if argv[1] == "csv":
        why = same_csv(argv[2], argv[3], set(argv[4:]))
    else:
        why = same_json(argv[2], argv[3], argv[4] if len(argv) > 4 else "^$")
    if why:
        print(why)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
