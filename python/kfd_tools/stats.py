"""Paired statistics for kfd-compare, in plain Python (no numpy, so that the results do not
depend on a library version): summaries, the two-sided exact sign test, the Wilcoxon
signed-rank test (exact, with ties and zeros) and a seeded bootstrap interval of the median
ratio. Lower values are better everywhere (errors, CPU time)."""
import functools
import math
import random

TIE_TOLERANCE = 1e-12  # relative: |a - b| <= tol * max(|a|, |b|) is a tie


def quantile(values, q):
    """Linear-interpolation quantile (numpy's default, 'linear'), q in [0, 1]."""
    v = sorted(values)
    if not v:
        return math.nan
    pos = (len(v) - 1) * q
    lo = math.floor(pos)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (pos - lo)


def median(values):
    return quantile(values, 0.5)


def summary(values):
    """n, median, q1, q3 (IQR = q3 - q1), mean and sample standard deviation (n - 1)."""
    v = [x for x in values if x is not None and not math.isnan(x)]
    n = len(v)
    if n == 0:
        return {"n": 0, "median": math.nan, "q1": math.nan, "q3": math.nan, "mean": math.nan,
                "std": math.nan}
    mean = sum(v) / n
    std = math.sqrt(sum((x - mean) ** 2 for x in v) / (n - 1)) if n > 1 else 0.0
    return {"n": n, "median": median(v), "q1": quantile(v, 0.25), "q3": quantile(v, 0.75),
            "mean": mean, "std": std}


def compare(a, b):
    """-1 when a is better (lower) than b, +1 when worse, 0 for a tie."""
    if abs(a - b) <= TIE_TOLERANCE * max(abs(a), abs(b)):
        return 0
    return -1 if a < b else 1


def wins_losses_ties(a, b):
    """Counts over pairs (a_i, b_i): a better (wins), worse (losses), equal (ties)."""
    w = l = t = 0
    for x, y in zip(a, b):
        c = compare(x, y)
        if c < 0:
            w += 1
        elif c > 0:
            l += 1
        else:
            t += 1
    return w, l, t


def sign_test(wins, losses):
    """Two-sided exact sign test: ties left out, p = P(min count this extreme or more) under
    Binomial(n, 1/2), doubled, capped at 1. n = 0 gives p = 1."""
    n = wins + losses
    if n == 0:
        return 1.0
    k = min(wins, losses)
    tail = sum(math.comb(n, i) for i in range(k + 1)) / 2 ** n
    return min(1.0, 2.0 * tail)


@functools.lru_cache(maxsize=None)
def smallest_p(n):
    """The smallest two-sided p the exact sign test and the exact Wilcoxon signed-rank test can
    give for n paired runs: every difference of one sign (and, for Wilcoxon, all |d| distinct).
    When it is >= a level alpha, no difference can be significant at that level. n = 0 gives 1."""
    if n <= 0:
        return 1.0
    return min(sign_test(n, 0), wilcoxon(list(range(1, n + 1)), [0] * n)[2])


def ranks(values):
    """Ranks from 1, ties given their average rank."""
    order = sorted(range(len(values)), key=lambda i: values[i])
    r = [0.0] * len(values)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and values[order[j + 1]] == values[order[i]]:
            j += 1
        avg = (i + j) / 2.0 + 1.0
        for k in range(i, j + 1):
            r[order[k]] = avg
        i = j + 1
    return r


def wilcoxon(a, b):
    """Wilcoxon signed-rank test of the differences d_i = a_i - b_i, two-sided, exact.
    Differences that are ties (see compare) are dropped (Wilcoxon's method); |d| is ranked
    with average ranks for equal values; W+ is the sum of the ranks of positive d. The p-value
    is exact under H0 (every sign equally likely) for these (possibly tied) ranks, by counting
    sign patterns on doubled ranks: p = min(1, 2 min(P(W+ <= w), P(W+ >= w))).
    Returns (W+, n used, p); no difference left gives (0, 0, 1)."""
    d = [x - y for x, y in zip(a, b) if compare(x, y) != 0]
    n = len(d)
    if n == 0:
        return 0.0, 0, 1.0
    absd = [abs(x) for x in d]
    # Equal |d| up to rounding share a rank: group values within the tie tolerance.
    rounded = [float("%.12g" % x) for x in absd]
    r = ranks(rounded)
    w_plus = sum(ri for ri, di in zip(r, d) if di > 0)
    twice = [int(round(2 * ri)) for ri in r]  # average ranks are multiples of 1/2
    total = sum(twice)
    counts = [0] * (total + 1)  # counts[s]: sign patterns whose doubled W+ is s
    counts[0] = 1
    for t in twice:
        for s in range(total, t - 1, -1):
            counts[s] += counts[s - t]
    w2 = int(round(2 * w_plus))
    patterns = 2 ** n
    lower = sum(counts[: w2 + 1]) / patterns
    upper = sum(counts[w2:]) / patterns
    return w_plus, n, min(1.0, 2.0 * min(lower, upper))


def bootstrap_median_ratio(a, b, resamples=2000, seed=1, level=0.95):
    """Median of the paired ratios a_i / b_i (pairs with b_i <= 0 or a missing value left out)
    and its percentile bootstrap interval: `resamples` resamplings of the pairs with
    replacement, drawn with random.Random(seed), so the same inputs and seed give the same
    interval. Returns (median ratio, low, high); nan when no pair is usable."""
    r = [x / y for x, y in zip(a, b) if y is not None and x is not None and y > 0]
    if not r:
        return math.nan, math.nan, math.nan
    rng = random.Random(seed)
    n = len(r)
    meds = sorted(median([r[rng.randrange(n)] for _ in range(n)]) for _ in range(resamples))
    alpha = (1.0 - level) / 2.0
    return median(r), quantile(meds, alpha), quantile(meds, 1.0 - alpha)


def paired(a, b, seed=1):
    """Everything kfd-compare reports for one pair of matched samples (a against b)."""
    w, l, t = wins_losses_ties(a, b)
    _, n_w, p_w = wilcoxon(a, b)
    ratio, lo, hi = bootstrap_median_ratio(a, b, seed=seed)
    return {"n": len(a), "wins": w, "losses": l, "ties": t, "p_sign": sign_test(w, l),
            "p_wilcoxon": p_w, "n_wilcoxon": n_w, "median_ratio": ratio, "ratio_lo": lo,
            "ratio_hi": hi}


def rank_sum_greater(x, y):
    """One-sided exact rank-sum (Mann-Whitney) test that the values x tend to be larger than
    the values y: the ranks of x and y pooled (average ranks for equal values), p = the share
    of the C(n+m, n) ways to give n of the pooled ranks to x whose sum is at least x's. Exact
    for any ties (doubled ranks are counted). Returns 1 when x or y is empty."""
    if not x or not y:
        return 1.0
    r = ranks([float("%.12g" % v) for v in list(x) + list(y)])
    twice = [int(round(2 * ri)) for ri in r]
    n, total = len(x), sum(twice)
    observed = sum(twice[:n])
    counts = [[0] * (total + 1) for _ in range(n + 1)]  # counts[k][s]: k ranks summing to s
    counts[0][0] = 1
    for t in twice:
        for k in range(n, 0, -1):
            row, below = counts[k], counts[k - 1]
            for s in range(total, t - 1, -1):
                if below[s - t]:
                    row[s] += below[s - t]
    return sum(counts[n][observed:]) / math.comb(len(twice), n)
