"""kfd-compare's judgement of its runs (issue 22, item 5) and the report.md and summary.md drawn
from it: which runs failed, the worst run of each mode, one verdict per log, config and pair,
a warning when there are too few runs for any p < 0.05, and a reason for every "–".

A run fails when it did not finish, when it has no value of an error metric its log gives, or
when that error is above F x the baseline mode's median on the same log and config. The error
metrics judged are the local and long relations error, or ATE on a log without relations.
Verdicts: see VERDICT_RULE. The statistics themselves are stats.py's."""
import posixpath
import re

from . import agreement as kfd_agreement
from . import stats as kfd_stats

ALPHA = 0.05  # level of every "significant"
FAILURE_FACTOR = 3.0  # default F of the failure rule (--failure-factor)
# (metric key, label, unit): what every table and plot reports
METRICS = [("local", "relations error, local", "m"), ("long", "relations error, long", "m"),
           ("all", "relations error, all", "m"), ("ate", "ATE RMSE", "m"),
           ("drop", "dropped", "%"), ("cpu", "CPU (user+sys)", "s"),
           ("cpu_ms_per_scan", "CPU per scan", "ms")]
PAIR_METRICS = ["local", "long", "all", "ate", "cpu"]
NAMED_PAIRS = [("kfd", "odometry@kfd"), ("kfd", "keyframe"), ("kfd+lo", "decimate@kfd+lo"),
               ("kfd", "decimate@kfd")]
NAMES = {"local": "local error", "long": "long error", "all": "relations error", "ate": "ATE",
         "drop": "drop rate", "cpu": "CPU time", "cpu_ms_per_scan": "CPU per scan",
         "icp_rejected": "ICP rejection count", "lost_tracks": "lost-track count"}
DIGITS = {"drop": 1, "cpu": 2, "cpu_ms_per_scan": 2, "icp_rejected": 1, "lost_tracks": 1}
COUNTS = [("icp_rejected", "ICP rejected"), ("lost_tracks", "lost tracks")]  # per run, no GT needed
SUPERSCRIPT = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")

FAILURE_RULE = (
    "A run **failed** when it did not finish (kfd-icp-slam exited with an error or was killed, "
    "or its job stopped before writing run.json), when it has no value of an error metric its "
    "log gives, or when its local or long relations error (ATE on a log with ground truth and "
    "no relations) is above F = %g × the median of that error over the baseline mode `%s`'s "
    "runs on the same log and config; the baseline's own runs are judged the same way.")
VERDICT_RULE = (
    "Verdict per log, config and pair A vs B, on the local and long relations error (ATE on a "
    "log without relations) over the repeats both modes ran: **WORSE** when A is significantly "
    "worse on one of them (exact Wilcoxon signed-rank p < %(alpha)g and median ratio A/B > 1) "
    "or A has failed runs and B none; **BETTER** when A is significantly better on one of them "
    "(p < %(alpha)g and ratio < 1), not significantly worse on the other and has no more failed "
    "runs than B; otherwise **NO SIGNIFICANT DIFFERENCE**. The CPU ratio is the median of the "
    "per-run ratios A/B with its bootstrap 95 %% interval. The exact two-sided tests cannot give "
    "p < %(alpha)g with fewer than %(needed)d paired runs (n = 5: at best p = %(p5).2g): the "
    "verdict and the pair table then say that no difference can be significant.")


# --- formatting ------------------------------------------------------------------------------

def fmt(x, digits=3):
    """A number for a table; None or nan is '–' (callers that can give a reason use Dashes)."""
    if x is None or x != x:
        return "–"
    return ("%." + str(digits) + "f") % x


def fmt3(x):
    """Three significant digits (0.0163, 1.30, 28.5), for errors of any scale in a sentence."""
    return "%.0f" % x if abs(x) >= 100 else "%#.3g" % x


def fmt_p(p):
    return "%.2g" % p if p < 0.01 else "%.2f" % p


def plural(n, word):
    return "%d %s%s" % (n, word, "" if n == 1 else "s")


class Dashes:
    """The "–" cells of one table, each marked with the footnote of its reason; legend() is
    written under the table."""

    def __init__(self):
        self.reasons = []

    def __call__(self, reason):
        if reason not in self.reasons:
            self.reasons.append(reason)
        return "–" + self.marker(self.reasons.index(reason))

    @staticmethod
    def marker(i):
        return str(i + 1).translate(SUPERSCRIPT)

    def legend(self):
        return [""] + ["- –%s %s" % (self.marker(i), r) for i, r in enumerate(self.reasons)] \
            if self.reasons else []


# --- runs ------------------------------------------------------------------------------------

def finished(r):
    """False for the record of a run that did not finish (run_job, load_runs)."""
    return r.get("finished", True)


def run_folder(r):
    """A run's folder relative to OUT."""
    return posixpath.join("runs", r["log"], r["config"], r["mode"], "r%02d" % r["repeat"])


def has(runs, m):
    return any(r.get(m) is not None for r in runs)


def judged_metrics(runs):
    """The errors failures and verdicts are judged on: the local and long relations error the
    log gives, else ATE; none when the log has neither."""
    return [m for m in ("local", "long") if has(runs, m)] or (["ate"] if has(runs, "ate") else [])


def worst_key(judged):
    """What ranks the runs for the worst run: the long error, local without long relations."""
    return next((m for m in ("long", "local", "ate") if m in judged), None)


def failure_limits(baseline_runs, judged, factor):
    """metric -> baseline median and threshold F x median, over the baseline runs with a value."""
    limits = {}
    for m in judged:
        values = [r[m] for r in baseline_runs if r.get(m) is not None]
        if values:
            med = kfd_stats.median(values)
            limits[m] = {"baseline_median": med, "threshold": factor * med}
    return limits


def failure_reasons(r, judged, limits, factor, baseline):
    """Why run r failed (empty when it did not)."""
    if not finished(r):
        return ["did not finish: " + r.get("error", "no reason recorded")]
    reasons = []
    for m in judged:
        if r.get(m) is None:
            reasons.append("no %s" % NAMES[m])
        elif m in limits and r[m] > limits[m]["threshold"]:
            reasons.append("%s %s m > %g × %s's median %s m" % (
                NAMES[m], fmt(r[m]), factor, baseline, fmt(limits[m]["baseline_median"])))
    return reasons


def split_seconds(command):
    if "--split-seconds" in command:
        return float(command[command.index("--split-seconds") + 1])
    return None


# --- one log and config ----------------------------------------------------------------------

class Group:
    """The runs of one log and config (modes: mode -> {repeat: run}) and what is judged on them.
    Marks every run with failed, failure (its reasons) and folder."""

    def __init__(self, log, config, modes, baseline, factor, extra_pairs=(), trajectories=None):
        self.log, self.config, self.modes = log, config, modes
        self.baseline, self.factor = baseline, factor
        self.runs = [r for rs in modes.values() for r in rs.values()]
        self.judged = judged_metrics(self.runs)
        self.limits = failure_limits(self.mode_runs(baseline), self.judged, factor)
        for r in self.runs:
            reasons = failure_reasons(r, self.judged, self.limits, factor, baseline)
            r["failed"], r["failure"] = bool(reasons), "; ".join(reasons) or None
            r["folder"] = run_folder(r)
        self.order = sorted(modes, key=lambda m: (m != baseline, m))
        self.summary = {mode: {m: kfd_stats.summary([r.get(m) for r in self.mode_runs(mode)])
                               for m in [x[0] for x in METRICS + COUNTS]}
                        for mode in self.order}
        self.icp = icp_schedule(self.runs)
        self.agreement = self.agreements(trajectories) if trajectories else {}
        self.worst = {mode: self.worst_run(mode) for mode in self.order}
        self.pairs = self.wanted_pairs(extra_pairs)
        self.results = {p: {m: self.paired(p[0], p[1], m) for m in PAIR_METRICS}
                        for p in self.pairs}
        self.verdicts = {p: self.verdict(*p) for p in self.pairs}

    def mode_runs(self, mode):
        return list(self.modes.get(mode, {}).values())

    def agreements(self, trajectories):
        """mode -> agreement.judge of its trajectories against the baseline's (None when
        there is nothing to compare); trajectories(run) gives a finished run's poses."""
        if self.baseline not in self.modes:
            return {}

        def of(mode):
            runs = [r for r in self.mode_runs(mode) if finished(r)]
            found = {r["repeat"]: t for r in runs for t in [trajectories(r)] if t}
            return kfd_agreement.Trajectories(found, max_dt(runs))
        base = of(self.baseline)
        return {m: kfd_agreement.judge(of(m), base) for m in self.order if m != self.baseline}

    def failed(self, mode, repeats=None):
        return sum(1 for k, r in self.modes[mode].items()
                   if r["failed"] and (repeats is None or k in repeats))

    def worst_run(self, mode):
        key = worst_key(self.judged)
        runs = [r for r in self.mode_runs(mode) if key and r.get(key) is not None]
        return max(runs, key=lambda r: r[key]) if runs else None

    def wanted_pairs(self, extra):
        b = self.baseline
        wanted = [(m, b) for m in sorted(self.modes) if m != b and b in self.modes]
        for p in NAMED_PAIRS + list(extra):
            if p[0] in self.modes and p[1] in self.modes and p not in wanted:
                wanted.append(p)
        return wanted

    def common(self, a, b):
        return sorted(set(self.modes[a]) & set(self.modes[b]))

    def paired(self, a, b, m):
        """stats.paired over the repeats where both modes have a value of m, with both medians;
        None when there is no such repeat."""
        xs = [(self.modes[a][k].get(m), self.modes[b][k].get(m)) for k in self.common(a, b)]
        xs = [(x, y) for x, y in xs if x is not None and y is not None]
        if not xs:
            return None
        res = kfd_stats.paired([x for x, _ in xs], [y for _, y in xs])
        res.update(median_a=kfd_stats.median([x for x, _ in xs]),
                   median_b=kfd_stats.median([y for _, y in xs]))
        return res

    # why a value is missing

    def absent(self, m):
        """Why no run of this log and config has a value of m."""
        commands = [r["command"] for r in self.runs if finished(r) and r.get("command")]
        if not commands:
            return "no run of this log finished"
        if m == "ate":
            if not any("--gt" in c for c in commands):
                return "no ground-truth trajectory (.gt.tum) for this log"
            return "no estimated pose matched a ground-truth pose"
        if m in ("local", "long", "all"):
            if not any("-g" in c for c in commands):
                return "no relations file for this log"
            if not has(self.runs, "all"):
                return "no relation of this log matched the estimated poses"
            s = split_seconds(commands[0])
            return "no relation of this log spans %s %s s (--split-seconds)" % (
                "at most" if m == "local" else "more than", "S" if s is None else "%g" % s)
        return "no run of this log has a %s value" % NAMES[m]

    def why_missing(self, m, mode):
        """Why mode has no value of m on this log and config."""
        runs = self.mode_runs(mode)
        if not runs:
            return "no run of %s" % mode
        if not has(self.runs, m) and any(finished(r) for r in self.runs):
            return self.absent(m)  # the log does not give m
        if not any(finished(r) for r in runs):
            return "no run of %s finished" % mode
        return "no finished run of %s has a %s value (failed runs)" % (mode, NAMES[m])

    def why_unpaired(self, m, a, b):
        """Why the pair a vs b has no result for m."""
        if not has(self.runs, m):
            return self.why_missing(m, a)
        for mode in (a, b):
            if not has(self.mode_runs(mode), m):
                return self.why_missing(m, mode)
        return "no repeat has a %s value in both %s and %s" % (NAMES[m], a, b)

    def why_cell(self, m, r):
        """Why run r has no value of m."""
        if not has(self.runs, m):
            return self.absent(m)
        return "this run has no %s value (it failed)" % NAMES[m]

    # verdicts

    def verdict(self, a, b):
        res = self.results[(a, b)]
        decisive = [res[m] for m in self.judged if res[m]] or [x for x in res.values() if x]
        n = max((x["n"] for x in decisive), default=0)
        repeats = set(self.common(a, b))
        fa, fb = self.failed(a, repeats), self.failed(b, repeats)
        worse = [m for m in self.judged if significant(res[m], +1)]
        better = [m for m in self.judged if significant(res[m], -1)]
        spread = self.agreement.get(a) if b == self.baseline else None
        if not self.judged:
            word = spread_word(spread, b, fa > fb and fb == 0)
        elif worse or (fa > fb and fb == 0):
            word = "WORSE"
        elif better and fa <= fb:
            word = "BETTER"
        else:
            word = "NO SIGNIFICANT DIFFERENCE"
        cpu = res["cpu"]
        v = {"log": self.log, "config": self.config, "a": a, "b": b, "verdict": word,
             "worse_on": worse, "better_on": better, "failed_a": fa, "failed_b": fb,
             "repeats": len(repeats), "n": n, "smallest_p": kfd_stats.smallest_p(n),
             "cpu_ratio": cpu["median_ratio"] if cpu else None,
             "cpu_lo": cpu["ratio_lo"] if cpu else None,
             "cpu_hi": cpu["ratio_hi"] if cpu else None, "icp": self.icp,
             "spread": spread}
        v["small_n"] = v["smallest_p"] >= ALPHA and bool(self.judged)
        v["text"] = self.verdict_text(v, res)
        return v

    def verdict_text(self, v, res):
        a, b = v["a"], v["b"]
        evidence = []
        for m in self.judged:
            x = res[m]
            evidence.append("%s: %s" % (NAMES[m], self.why_unpaired(m, a, b)) if x is None else
                            "%s %s vs %s m, Wilcoxon p = %s" % (
                                NAMES[m], fmt3(x["median_a"]), fmt3(x["median_b"]),
                                fmt_p(x["p_wilcoxon"])))
        if not self.judged:
            evidence.append(self.spread_text(a, b, v["spread"]))
        evidence.append(self.counts_text(a, b))
        evidence.append("%s vs %d" % (plural(v["failed_a"], "failed run"), v["failed_b"]))
        cpu = res["cpu"]
        if cpu and cpu["median_ratio"] == cpu["median_ratio"]:
            at = "at CPU ratio %s [%s–%s]" % (fmt(cpu["median_ratio"], 2),
                                              fmt(cpu["ratio_lo"], 2), fmt(cpu["ratio_hi"], 2))
        else:
            at = "CPU ratio unknown (%s)" % (self.why_unpaired("cpu", a, b) if cpu is None
                                            else "%s's CPU time is 0 in every pair" % b)
        return "%s, %s: %s vs %s — %s (%s) %s, %s" % (
            self.log, self.config, a, b, v["verdict"], "; ".join(evidence), at, self.icp)

    def spread_text(self, a, b, sp):
        """The evidence of a verdict without ground truth (agreement.judge's result sp)."""
        if sp is None:
            return ("no ground truth (%s; %s) and no two finished %s runs with a trajectory to "
                    "measure %s's own spread" % (self.absent("all"), self.absent("ate"), b, b))
        if sp.get("still"):
            sc = sp["scatter"]
            return ("no ground truth, but the sensor stands still (every %s run's positions "
                    "within %g m of their mean, heading within %g°): its one true pose makes "
                    "each run's scatter about its mean its error: %s %s m vs %s %s m (medians "
                    "over %d and %d runs; largest %s vs %s m); rank-sum p = %s" % (
                        b, kfd_agreement.STILL_M, kfd_agreement.STILL_DEG, a,
                        fmt3(sc["mode"]), b, fmt3(sc["baseline"]), sp["n"], sp["n_spread"],
                        fmt3(sc["mode_max"]), fmt3(sc["baseline_max"]), fmt_p(sc["p"])))
        ate, drift = sp["ate"], sp["drift"]

        def pct(x):
            return "–" if x is None else "%.2g %%/m" % (100 * x)
        return ("no ground truth: %s's trajectory vs %s's of the same repeat: ATE %s m, drift %s "
                "(medians over %d runs); %s's own repeats differ by %s m, %s (largest %s m, %s); "
                "beyond %s's largest in %d of %d runs; rank-sum p = %s (ATE), %s (drift)" % (
                    a, b, fmt3(ate["departure"]), pct(drift["departure"]), sp["n"], b,
                    fmt3(ate["spread"]), pct(drift["spread"]), fmt3(ate["spread_max"]),
                    pct(drift["spread_max"]), b, sp["beyond"], sp["n"], fmt_p(ate["p"]),
                    fmt_p(drift["p"])))

    def counts_text(self, a, b):
        """ICP rejections and suspected lost tracks, medians per run (they need no ground
        truth)."""
        def med(mode, m):
            s = self.summary[mode][m]
            return "–" if s["n"] == 0 else "%g" % s["median"]
        return "; ".join("%s %s vs %s" % (label, med(a, m), med(b, m)) for m, label in COUNTS) \
            + " (medians)"


def spread_word(sp, b, more_failures):
    """The verdict word without ground truth, with how far A's departure is from b's spread
    (the ratio of the medians, ATE)."""
    if sp is None:
        return "CANNOT JUDGE"
    if sp.get("still"):  # a sensor standing still: each run's scatter is its error
        sc = sp["scatter"]
        ratio = sc["mode"] / sc["baseline"] if sc["baseline"] else None
        times = " (%.2f× its scatter)" % ratio if ratio is not None else ""
        if sp["departs"] or more_failures:
            return "SCATTERS MORE THAN %s%s" % (b.upper(), times)
        return "SCATTERS NO MORE THAN %s%s" % (b.upper(), times)
    ratio = sp["ate"]["departure"] / sp["ate"]["spread"] if sp["ate"]["spread"] else None
    times = " (%.2f× its median)" % ratio if ratio is not None else ""
    if sp["departs"] or more_failures:
        return "BEYOND %s'S SPREAD%s" % (b.upper(), times)
    return "WITHIN %s'S SPREAD%s" % (b.upper(), times)


def max_dt(runs):
    """The stamp tolerance the runs' ground truth was matched with (--max-dt), else 1 ms."""
    for r in runs:
        c = r.get("command") or []
        if "--max-dt" in c:
            return float(c[c.index("--max-dt") + 1])
    return 1e-3


def icp_schedule(runs):
    """Which ICP config the runs' CPU ratio holds for: icp_schedule_of their config file."""
    return icp_schedule_of(next((r["command"][1] for r in runs
                                 if len(r.get("command") or []) > 1), None))


def icp_schedule_of(path):
    """'ICP on every scan' or 'ICP after L m / A deg of odometry', read from a kfd-icp-slam
    config (icp-slam's localizationLinDistance and localizationAngDistance)."""
    try:
        with open(path) as f:
            text = f.read()
    except (OSError, TypeError):
        return "ICP config unknown (its file is not readable)"
    found = {k: float(v) for k, v in re.findall(
        r"^\s*localization(Lin|Ang)Distance\s*=\s*([0-9.eE+-]+)", text, re.M)}
    lin, ang = found.get("Lin"), found.get("Ang")
    if lin is None or ang is None:
        return "ICP config %s (no localizationLinDistance/AngDistance)" % posixpath.basename(path)
    if lin == 0 and ang == 0:
        return "ICP on every scan"
    return "ICP after %g m / %g° of odometry" % (lin, ang)


def significant(res, direction):
    """res (stats.paired) shows A significantly worse (direction +1) or better (-1) than B."""
    return res is not None and res["p_wilcoxon"] < ALPHA and \
        (res["median_ratio"] - 1.0) * direction > 0


def runs_needed(alpha):
    """The fewest paired runs with which an exact two-sided test can give p < alpha."""
    n = 1
    while kfd_stats.smallest_p(n) >= alpha:
        n += 1
    return n


def small_n_warning(n):
    if n == 0:
        return "n = 0: no repeat has an error value in both modes; nothing can be compared"
    return "n = %d: the smallest possible p is %.2g; no difference can be significant" % (
        n, kfd_stats.smallest_p(n))


# --- all groups, runs.json --------------------------------------------------------------------

def analyse(runs, baseline, extra_pairs=(), factor=FAILURE_FACTOR, trajectories=None):
    """The groups (log, config) of the runs, judged; and runs.json's content. trajectories(run)
    gives a run's poses for the verdict without ground truth (agreement.py)."""
    by = {}
    for r in runs:
        by.setdefault((r["log"], r["config"]), {}).setdefault(r["mode"], {})[r["repeat"]] = r
    groups = [Group(log, config, modes, baseline, factor, extra_pairs, trajectories)
              for (log, config), modes in sorted(by.items())]
    stats = {"baseline": baseline, "failure_factor": factor, "alpha": ALPHA,
             "failure_rule": FAILURE_RULE % (factor, baseline),
             "verdict_rule": VERDICT_RULE % {"alpha": ALPHA, "p5": kfd_stats.smallest_p(5),
                                             "needed": runs_needed(ALPHA)},
             "runs": runs, "summary": [],
             "failure_thresholds": [], "worst": [], "pairs": [], "verdicts": []}
    for g in groups:
        where = {"log": g.log, "config": g.config}
        for m, lim in sorted(g.limits.items()):
            stats["failure_thresholds"].append(dict(where, metric=m, **lim))
        for mode in g.order:
            runs_m = g.mode_runs(mode)
            stats["summary"].append(dict(where, mode=mode, n_runs=len(runs_m),
                                         failed=g.failed(mode), **g.summary[mode]))
            w = g.worst[mode]
            if w:
                stats["worst"].append(dict(where, mode=mode, by=worst_key(g.judged),
                                           repeat=w["repeat"], local=w.get("local"),
                                           long=w.get("long"), ate=w.get("ate"),
                                           folder=w["folder"]))
        for (a, b), ms in g.results.items():
            for m in PAIR_METRICS:
                if ms[m]:
                    stats["pairs"].append(dict(ms[m], metric=m, a=a, b=b, **where))
            stats["verdicts"].append(g.verdicts[(a, b)])
    return groups, stats


# --- report.md ---------------------------------------------------------------------------------

def header(stats):
    return [stats["failure_rule"], "", stats["verdict_rule"], "",
            "A \"–\" in a table carries a footnote marker; the reason is under the table.", ""]


def threshold_line(g):
    if not g.judged:
        return "No error metric on this log (%s; %s): only runs that did not finish fail." % (
            g.absent("all"), g.absent("ate"))
    if not g.limits:
        return ("No `%s` run with an error value on this log: only runs that did not finish or "
                "have no error value fail." % g.baseline)
    return "A run fails above: %s." % ", ".join(
        "%s %s m (%g × %s's median %s m)" % (NAMES[m], fmt(lim["threshold"]), g.factor,
                                             g.baseline, fmt(lim["baseline_median"]))
        for m, lim in sorted(g.limits.items()))


def median_cell(g, mode, m, dashes, iqr=True):
    s = g.summary[mode][m]
    if s["n"] == 0:
        return dashes(g.why_missing(m, mode))
    d = DIGITS.get(m, 3)
    return fmt(s["median"], d) + (" [%s–%s]" % (fmt(s["q1"], d), fmt(s["q3"], d)) if iqr else "")


def failed_cell(g, mode):
    return "%d/%d" % (g.failed(mode), len(g.modes[mode]))


def mode_table(g):
    dashes = Dashes()
    cols = ["drop", "local", "long", "all", "ate", "cpu", "cpu_ms_per_scan", "icp_rejected",
            "lost_tracks"]
    lines = ["| mode | n | failed | dropped % | local (m) | long (m) | all (m) | ATE (m) | CPU (s) "
             "| CPU/scan (ms) | ICP rejected | lost tracks |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for mode in g.order:
        lines.append("| %s | %d | %s | %s |" % (mode, len(g.modes[mode]), failed_cell(g, mode),
                                                " | ".join(median_cell(g, mode, m, dashes)
                                                           for m in cols)))
    return lines + dashes.legend()


def worst_cells(g, mode, dashes):
    """repeat, local, long, ATE, ICP rejected / lost tracks, folder of mode's worst run."""
    w = g.worst[mode]
    if w is None:
        return [dashes(g.why_missing(worst_key(g.judged), mode))] * 6
    icp = ("%d / %d" % (w["icp_rejected"], w["lost_tracks"])
           if w.get("icp_rejected") is not None and w.get("lost_tracks") is not None
           else dashes("kfd-icp-slam did not report ICP's corrections (a run before issue 22)"))
    return ["r%02d" % w["repeat"]] + [
        fmt(w[m]) if w.get(m) is not None else dashes(g.why_cell(m, w))
        for m in ("local", "long", "ate")] + [icp, "`%s`" % w["folder"]]


def worst_table(g):
    key = worst_key(g.judged)
    if key is None:
        return ["No worst run: no error metric on this log."]
    dashes = Dashes()
    lines = ["Worst run per mode (largest %s; its folder, relative to OUT, has its map figure "
             "when run with --maps):" % NAMES[key], "",
             "| mode | repeat | local (m) | long (m) | ATE (m) | ICP rejected / lost tracks | "
             "folder |",
             "|---|---:|---:|---:|---:|---:|---|"]
    for mode in g.order:
        lines.append("| %s | %s |" % (mode, " | ".join(worst_cells(g, mode, dashes))))
    return lines + dashes.legend()


def failed_list(g):
    failed = [r for mode in g.order for r in g.mode_runs(mode) if r["failed"]]
    if not failed:
        return ["No failed run."]
    return ["Failed runs:", ""] + ["- %s r%02d (`%s`): %s" % (r["mode"], r["repeat"],
                                                             r["folder"], r["failure"])
                                   for r in failed]


def ratio_cell(res, b, dashes, digits=3):
    if res["median_ratio"] != res["median_ratio"]:
        return dashes("ratio undefined: %s's value is 0 in every pair" % b)
    return "%s [%s–%s]" % (fmt(res["median_ratio"], digits), fmt(res["ratio_lo"], digits),
                           fmt(res["ratio_hi"], digits))


def small_n_notes(verdicts):
    """One warning per number of paired runs too small for any p < ALPHA, naming the verdicts
    it concerns (said once, not under every verdict)."""
    by_n = {}
    for v in verdicts:
        if v["small_n"]:
            by_n.setdefault(v["n"], []).append("%s vs %s on %s" % (v["a"], v["b"], v["log"]))
    return ["", *["**Warning** (%s): %s." % (", ".join(which), small_n_warning(n))
                  for n, which in sorted(by_n.items())]] if by_n else []


def pair_table(g):
    if not g.pairs:
        return []
    dashes = Dashes()
    lines = ["| A vs B | metric | n | W/L/T | p sign | p Wilcoxon | ratio A/B [95 %] |",
             "|---|---|---:|---:|---:|---:|---:|"]
    for a, b in g.pairs:
        for m in PAIR_METRICS:
            res = g.results[(a, b)][m]
            if res is None:  # a metric no repeat of both modes has: no row
                continue
            lines.append("| %s vs %s | %s | %d | %d/%d/%d | %s | %s | %s |" % (
                a, b, m, res["n"], res["wins"], res["losses"], res["ties"],
                fmt_p(res["p_sign"]), fmt_p(res["p_wilcoxon"]), ratio_cell(res, b, dashes)))
    return lines + dashes.legend()


def verdict_lines(g):
    return ["- " + g.verdicts[p]["text"] for p in g.pairs] or [no_pair_line(g)]


def no_pair_line(g):
    """Why a group has no verdict: the baseline has no runs, or nothing to compare it with."""
    if g.baseline not in g.modes:
        return "No pair to judge: no `%s` runs (the baseline) and no named pair." % g.baseline
    return ("No pair to judge: `%s` (the baseline) is the only mode run; run another mode "
            "beside it (--modes) to get a verdict." % g.baseline)


def spread_line(g):
    """For a log with ground truth, what the verdict without it would have said (the same
    measure a user's log without ground truth gets)."""
    found = [(a, sp) for a, sp in sorted(g.agreement.items()) if sp and not sp.get("still")]
    if not g.judged or not found:
        return []
    return ["Against %s's own spread (the verdict a log without ground truth gets): %s." % (
        g.baseline, "; ".join("%s %s (ATE to %s %s m vs %s m between its repeats, drift %.2g vs "
                              "%.2g %%/m, rank-sum p = %s / %s)" % (
                                  a, "beyond" if sp["departs"] else "within", g.baseline,
                                  fmt3(sp["ate"]["departure"]), fmt3(sp["ate"]["spread"]),
                                  100 * (sp["drift"]["departure"] or 0),
                                  100 * (sp["drift"]["spread"] or 0), fmt_p(sp["ate"]["p"]),
                                  fmt_p(sp["drift"]["p"])) for a, sp in found)), ""]


def report_md(groups, stats, out, plots):
    lines = ["# kfd-compare report", "",
             "%d runs under `%s`. Medians over repeats (repeat K skips the first K scans; "
             "simulated logs also use seed K + 1); IQR in brackets; lower is better. Paired "
             "comparisons match runs by repeat: W/L/T = runs where the first mode is better / "
             "worse / equal; p: two-sided exact sign test and exact Wilcoxon signed-rank test; "
             "ratio: median of the per-run ratios first/second with a bootstrap 95 %% interval "
             "(2000 resamples, seed 1). CPU is user + sys of kfd-icp-slam (the drop-rate "
             "matching pre-pass excluded); n counts every run, failed ones included, and a "
             "metric's median is over the runs that have it." % (len(stats["runs"]), out), ""]
    lines += header(stats)
    for g in groups:
        lines += ["## %s, %s" % (g.log, g.config), "", threshold_line(g), ""]
        lines += verdict_lines(g) + small_n_notes(g.verdicts.values()) + [""]
        lines += spread_line(g)
        lines += mode_table(g) + [""] + worst_table(g) + [""] + failed_list(g) + [""]
        lines += pair_table(g) + [""]
        if plots:
            lines += ["![%s %s](plots/%s-%s.png)" % (g.log, g.config, g.log, g.config), ""]
    return "\n".join(lines)


# --- summary.md --------------------------------------------------------------------------------

def summary_md(groups, stats):
    """summary.md, per config: the verdicts; per (log, mode) n, failed runs and medians; the
    worst run of each mode; per (log, pair) wins/losses and sign-test p for the local, long and
    all relations error and ATE, and the CPU ratio."""
    lines = ["# kfd-compare summary", ""] + header(stats)
    for config in sorted({g.config for g in groups}):
        gs = [g for g in groups if g.config == config]
        lines += ["## %s" % config, "", "Verdicts:", ""]
        lines += [line for g in gs for line in verdict_lines(g)]
        lines += small_n_notes([v for g in gs for v in g.verdicts.values()]) + [""]
        lines += summary_modes(gs) + [""] + summary_worst(gs) + [""] + summary_pairs(gs) + [""]
    return "\n".join(lines)


def summary_modes(gs):
    dashes = Dashes()
    lines = ["| log | mode | n | failed | dropped % | local (m) | long (m) | ATE (m) | CPU (s) | "
             "ICP rejected | lost tracks |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for g in gs:
        for mode in g.order:
            lines.append("| %s | %s | %d | %s | %s |" % (
                g.log, mode, len(g.modes[mode]), failed_cell(g, mode), " | ".join(
                    median_cell(g, mode, m, dashes, iqr=False)
                    for m in ("drop", "local", "long", "ate", "cpu", "icp_rejected",
                              "lost_tracks"))))
    return lines + dashes.legend()


def summary_worst(gs):
    dashes = Dashes()
    lines = ["Worst run per mode (largest long error, local without long relations, ATE "
             "without relations):", "",
             "| log | mode | by | repeat | local (m) | long (m) | ATE (m) | "
             "ICP rejected / lost tracks | folder |",
             "|---|---|---|---:|---:|---:|---:|---:|---|"]
    for g in gs:
        key = worst_key(g.judged)
        for mode in g.order:
            cells = [NAMES[key]] + worst_cells(g, mode, dashes) if key else \
                [dashes("no error metric on this log: %s; %s" % (g.absent("all"),
                                                                 g.absent("ate")))] * 7
            lines.append("| %s | %s | %s |" % (g.log, mode, " | ".join(cells)))
    return lines + dashes.legend()


def summary_pairs(gs):
    dashes = Dashes()
    lines = ["| log | A vs B | n | local W/L (p) | long W/L (p) | all W/L (p) | ATE W/L (p) | "
             "CPU ratio A/B [95 %] |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    for g in gs:
        for a, b in g.pairs:
            ms = g.results[(a, b)]

            def wl(m):
                p = ms[m]
                return dashes(g.why_unpaired(m, a, b)) if p is None else "%d/%d (%s)" % (
                    p["wins"], p["losses"], fmt_p(p["p_sign"]))
            cpu = dashes(g.why_unpaired("cpu", a, b)) if ms["cpu"] is None else \
                ratio_cell(ms["cpu"], b, dashes, 2)
            lines.append("| %s | %s vs %s | %d | %s | %s | %s | %s | %s |" % (
                g.log, a, b, g.verdicts[(a, b)]["n"], wl("local"), wl("long"), wl("all"),
                wl("ate"), cpu))
    return lines + dashes.legend()
