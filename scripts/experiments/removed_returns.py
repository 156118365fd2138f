#!/usr/bin/env python3
"""What kfd removed of a clean log's real returns (issue 25's "real returns kept" target), told
apart by what the raw scans just before and after saw at each removed return.

Usage: removed_returns.py RAW.clf[.gz] FILTERED.clf
  RAW.clf: every scan of the log (a CARMEN log; a rawlog first through
           `kfd-filter -c` with `pipeline = distance`, so that both sides count the same beams);
  FILTERED.clf: kfd-filter's output of the same log (removed beams written as 0).

For each valid return of a kept scan (0 < range < the laser's max range), the raw scans just
before and after it are motion-compensated by odometry and looked up along the bearing of the
return's world point: "repeated" when one of them has a return within 0.15 m + 2 % of the
range there (a static surface: what the removal should not touch), "seen_through" when one saw
beyond it (something that moved, a mixed pixel, or misalignment), else "unknown" (no return
there in either: dropouts, or out of their field of view). The same is given for a 1-in-10
sample of the returns kfd kept: the base rates of the test itself.
"""
import gzip
import math
import sys

TOL_M, TOL_FRACTION = 0.15, 0.02
CATEGORIES = ("repeated", "seen_through", "unknown")


def read_clf(path):
    """[(stamp, (x, y, theta) odometry, ranges)], the laser's max range and field of view."""
    opener = gzip.open if path.endswith(".gz") else open
    scans, max_range, resolution = [], float("inf"), None
    with opener(path, "rt") as f:
        for line in f:
            t = line.split()
            if len(t) >= 3 and t[0] == "PARAM" and t[1] == "robot_front_laser_max":
                max_range = float(t[2]) - 1e-3
            elif len(t) >= 3 and t[0] == "PARAM" and t[1] == "laser_front_laser_resolution":
                resolution = math.radians(float(t[2]))
            elif t and t[0] == "FLASER":
                n = int(t[1])
                ranges = [float(x) for x in t[2:2 + n]]
                rest = t[2 + n:]
                odometry = tuple(float(x) for x in rest[3:6])
                scans.append((float(rest[6]), odometry, ranges))
    n = len(scans[0][2]) if scans else 181
    fov = resolution * (n - 1) if resolution else math.pi
    return scans, max_range, fov


def main(raw_path, filtered_path):
    raw, max_range, fov = read_clf(raw_path)
    filtered, _, _ = read_clf(filtered_path)
    index = {round(s[0], 6): k for k, s in enumerate(raw)}
    usable = lambda r: 0.0 < r < max_range

    def verdict(k, x, y):
        v = "unknown"
        for j in (k - 1, k + 1):
            if not 0 <= j < len(raw):
                continue
            _, (ox, oy, ot), ranges = raw[j]
            a = (math.atan2(y - oy, x - ox) - ot + math.pi) % (2 * math.pi) - math.pi
            i = round((a + fov / 2) / fov * (len(ranges) - 1))
            if not 0 <= i < len(ranges) or not usable(ranges[i]):
                continue
            d = math.hypot(x - ox, y - oy)
            tol = TOL_M + TOL_FRACTION * d
            if abs(ranges[i] - d) <= tol:
                return "repeated"
            if ranges[i] > d + tol:
                v = "seen_through"
        return v

    valid = removed = 0
    removed_by = dict.fromkeys(CATEGORIES, 0)
    near_by = dict.fromkeys(CATEGORIES, 0)
    kept_by = dict.fromkeys(CATEGORIES, 0)
    for stamp, _, out in filtered:
        k = index.get(round(stamp, 6))
        if k is None:
            continue
        _, (ox, oy, ot), ranges = raw[k]
        for i, (r, r_out) in enumerate(zip(ranges, out)):
            if not usable(r):
                continue
            valid += 1
            is_removed = r_out == 0
            if not is_removed and i % 10:
                continue
            a = -fov / 2 + fov * i / (len(ranges) - 1) + ot
            v = verdict(k, ox + r * math.cos(a), oy + r * math.sin(a))
            if is_removed:
                removed += 1
                removed_by[v] += 1
                near_by[v] += r < 2.0
            else:
                kept_by[v] += 1
    sampled = max(1, sum(kept_by.values()))
    print("%s: %d valid returns in %d kept scans, %d removed (%.2f %%)" %
          (raw_path, valid, len(filtered), removed, 100.0 * removed / max(1, valid)))
    print("| verdict | removed | % of valid returns | % of removed | within 2 m | kept returns (sample) |")
    print("|---|---:|---:|---:|---:|---:|")
    for c in CATEGORIES:
        print("| %s | %d | %.2f | %.0f | %d | %.1f %% |" %
              (c, removed_by[c], 100.0 * removed_by[c] / max(1, valid),
               100.0 * removed_by[c] / max(1, removed), near_by[c], 100.0 * kept_by[c] / sampled))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__.split("\n\n")[1])
    main(sys.argv[1], sys.argv[2])
