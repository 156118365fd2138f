"""kfd-compare's verdict on a log without ground truth (issue 37, item 1).

Without relations or a ground-truth trajectory no run's error is known, but ICP-SLAM's own
run-to-run variation is: repeat K skips the first K scans, so the baseline mode's repeats are
the same problem solved again, and the difference between two of them is what "no change"
looks like. A mode A stays within the baseline's spread when its trajectory differs from the
baseline's of the same repeat no more than the baseline's repeats differ from each other.

Two trajectories are compared on the scans both have (stamps within max_dt):
- ATE: the RMS distance between matched positions after the 2D rigid alignment that fits them
  best (their start frames differ when their first scans differ);
- drift: over every stretch of SEGMENT_M metres of the second trajectory's path, the distance
  between the two trajectories' motions over that stretch, each in its own frame at the
  stretch's start, per metre travelled (median over the stretches).
The spread is the differences between the baseline's repeats K and K + 1; the departures are
A's repeat K against the baseline's repeat K. The verdict tests (one-sided exact rank sum) that
the departures are larger than the spread, on ATE and on drift.

A stretch counts for drift only when its ends are at least half its path apart: on a sensor
that stands still, ICP's jitter adds up to metres of "path" that is no motion at all.

A sensor that stands still (issue 37: every position of the baseline's runs within STILL_M of
their mean, its heading within STILL_DEG) has one true pose, so there the truth is known
without ground truth: each run's scatter (RMS distance of its positions from their mean) is
its error, and the verdict tests that the mode's scatter is larger than the baseline's."""
import math

from . import stats as kfd_stats

SEGMENT_M = 2.0  # m of path per drift stretch
ALPHA = 0.05
STILL_M = 0.10  # m: a baseline whose positions all lie this close to their mean stands still
STILL_DEG = 5.0  # deg: ... and whose heading stays within this of its mean


def match(a, b, max_dt):
    """Pairs of poses ((x, y, yaw) of a, (x, y, yaw) of b) whose stamps agree within max_dt;
    a and b are lists of (t, x, y, yaw) sorted by t."""
    pairs, j = [], 0
    for t, x, y, yaw in a:
        while j < len(b) and b[j][0] < t - max_dt:
            j += 1
        if j < len(b) and abs(b[j][0] - t) <= max_dt:
            pairs.append(((x, y, yaw), b[j][1:4]))
    return pairs


def fit(pairs):
    """The rotation and translation (c, s, tx, ty) that map the first positions of the pairs
    onto the second ones with the least squared distance (2D Kabsch)."""
    n = float(len(pairs))
    ax = sum(p[0][0] for p in pairs) / n
    ay = sum(p[0][1] for p in pairs) / n
    bx = sum(p[1][0] for p in pairs) / n
    by = sum(p[1][1] for p in pairs) / n
    sxx = sum((p[0][0] - ax) * (p[1][0] - bx) + (p[0][1] - ay) * (p[1][1] - by) for p in pairs)
    sxy = sum((p[0][0] - ax) * (p[1][1] - by) - (p[0][1] - ay) * (p[1][0] - bx) for p in pairs)
    theta = math.atan2(sxy, sxx)
    c, s = math.cos(theta), math.sin(theta)
    return c, s, bx - (c * ax - s * ay), by - (s * ax + c * ay)


def ate(pairs):
    """RMS distance between the matched positions after the best rigid alignment."""
    c, s, tx, ty = fit(pairs)
    return math.sqrt(sum((c * a[0] - s * a[1] + tx - b[0]) ** 2 +
                         (s * a[0] + c * a[1] + ty - b[1]) ** 2 for a, b in pairs) / len(pairs))


def local_motion(p0, p1):
    """p1's position in p0's frame."""
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    c, s = math.cos(p0[2]), math.sin(p0[2])
    return c * dx + s * dy, -s * dx + c * dy


def drift_per_m(pairs, segment_m=SEGMENT_M):
    """Median over the stretches of segment_m metres of the second trajectory's path of
    |motion of the first - motion of the second| / path length, each motion in its
    trajectory's frame at the stretch's start (the relative pose error per metre); None on a
    shorter path."""
    path = [0.0]
    for (_, b0), (_, b1) in zip(pairs, pairs[1:]):
        path.append(path[-1] + math.hypot(b1[0] - b0[0], b1[1] - b0[1]))
    values, j = [], 0
    for i in range(len(pairs)):
        while j < len(pairs) and path[j] - path[i] < segment_m:
            j += 1
        if j == len(pairs):
            break
        (a0, b0), (a1, b1) = pairs[i], pairs[j]
        if math.hypot(b1[0] - b0[0], b1[1] - b0[1]) < 0.5 * (path[j] - path[i]):
            continue  # jitter, not motion (a sensor standing still, or turning on the spot)
        ma, mb = local_motion(a0, a1), local_motion(b0, b1)
        values.append(math.hypot(ma[0] - mb[0], ma[1] - mb[1]) / (path[j] - path[i]))
    return kfd_stats.median(values) if values else None


def difference(a, b, max_dt):
    """ATE (m) and drift (per metre) of trajectory a against b, or None when fewer than 3
    poses match."""
    pairs = match(a, b, max_dt)
    if len(pairs) < 3:
        return None
    return {"ate": ate(pairs), "drift": drift_per_m(pairs), "matched": len(pairs)}


def spread(baseline):
    """The differences between the baseline's consecutive repeats: baseline is
    {repeat: trajectory}."""
    ks = sorted(baseline)
    return [d for k0, k1 in zip(ks, ks[1:])
            for d in [difference(baseline[k1], baseline[k0], baseline.max_dt)] if d]


class Trajectories(dict):
    """{repeat: trajectory} of one mode, with the stamp tolerance of its log."""

    def __init__(self, by_repeat, max_dt):
        super().__init__(by_repeat)
        self.max_dt = max_dt


def scatter(trajectory):
    """RMS distance (m) of a trajectory's positions from their mean, and its heading's largest
    distance from its circular mean (deg); None for an empty trajectory."""
    if not trajectory:
        return None
    n = float(len(trajectory))
    mx = sum(p[1] for p in trajectory) / n
    my = sum(p[2] for p in trajectory) / n
    rms = math.sqrt(sum((p[1] - mx) ** 2 + (p[2] - my) ** 2 for p in trajectory) / n)
    mean_yaw = math.atan2(sum(math.sin(p[3]) for p in trajectory),
                          sum(math.cos(p[3]) for p in trajectory))
    turn = max(abs(math.remainder(p[3] - mean_yaw, 2 * math.pi)) for p in trajectory)
    reach = max(math.hypot(p[1] - mx, p[2] - my) for p in trajectory)
    return {"rms": rms, "reach": reach, "turn_deg": math.degrees(turn)}


def still(baseline):
    """True when every run of the baseline stands still (STILL_M, STILL_DEG)."""
    found = [scatter(t) for t in baseline.values() if t]
    return bool(found) and all(f["reach"] <= STILL_M and f["turn_deg"] <= STILL_DEG
                               for f in found)


def judge_still(mode, baseline):
    """The verdict on a sensor that stands still: each run's scatter is its error."""
    x = [f["rms"] for f in (scatter(mode[k]) for k in sorted(mode)) if f]
    y = [f["rms"] for f in (scatter(baseline[k]) for k in sorted(baseline)) if f]
    if not x or not y:
        return None
    p = kfd_stats.rank_sum_greater(x, y)
    return {"still": True, "n": len(x), "n_spread": len(y),
            "scatter": {"mode": kfd_stats.median(x), "baseline": kfd_stats.median(y),
                        "mode_max": max(x), "baseline_max": max(y), "p": p},
            "beyond": sum(1 for v in x if v > max(y)), "departs": p < ALPHA}


def judge(mode, baseline):
    """The departures of mode (Trajectories) from baseline of the same repeats, the baseline's
    spread, and the tests; None when there is nothing to compare."""
    if still(baseline):
        return judge_still(mode, baseline)
    sp = spread(baseline)
    dep = [d for k in sorted(set(mode) & set(baseline))
           for d in [difference(mode[k], baseline[k], baseline.max_dt)] if d]
    if not sp or not dep:
        return None
    out = {"n": len(dep), "n_spread": len(sp)}
    for m in ("ate", "drift"):
        x = [d[m] for d in dep if d[m] is not None]
        y = [d[m] for d in sp if d[m] is not None]
        out[m] = {"departure": kfd_stats.median(x) if x else None,
                  "spread": kfd_stats.median(y) if y else None,
                  "spread_max": max(y) if y else None,
                  "beyond": sum(1 for v in x if y and v > max(y)),
                  "p": kfd_stats.rank_sum_greater(x, y)}
    out["beyond"] = sum(1 for d in dep if any(
        d[m] is not None and out[m]["spread_max"] is not None and d[m] > out[m]["spread_max"]
        for m in ("ate", "drift")))
    out["departs"] = any(out[m]["p"] < ALPHA for m in ("ate", "drift"))
    return out
