"""kfd-compare's judgement (issue 22, item 5) on hand-made output folders: failed runs (an error
above F x the baseline's median, a crashed run, a job that stopped), the worst run per mode, the
verdicts (better, worse by significance, worse by failures, no difference), the small-R warning
and the reasons of the "–" cells; and run_job's record of a failed kfd-icp-slam run."""
import argparse
import json
import math
import os
import random
import re
import shutil
import stat
import tempfile
import unittest

from kfd_tools import agreement as kfd_agreement
from kfd_tools import compare as kfd_compare
from kfd_tools import report as kfd_report
from kfd_tools import stats as kfd_stats

CONFIG = "cfg"
# The user's case of issue 22: kfd's long error per repeat against none's.
NONE_LONG = [1.0, 1.2, 1.3, 1.5, 1.65]
KFD_LONG = [0.60, 0.15, 2.72, 28.5, 15.8]


def command(relations=True, gt=False):
    """The parts of a run's command collect reads (what the log gives, --split-seconds)."""
    return (["kfd-icp-slam", CONFIG + ".ini", "x.rawlog", "-m", "m", "--split-seconds", "10.0"]
            + (["-g", "x.relations"] if relations else []) + (["--gt", "x.gt.tum"] if gt else []))


def run_path(out, log, mode, repeat):
    return os.path.join(out, "runs", log, CONFIG, mode, "r%02d" % repeat)


def write_run(out, log, mode, repeat, local=None, long=None, ate=None, cpu=10.0, **more):
    """A finished run's run.json (run_job's schema)."""
    folder = run_path(out, log, mode, repeat)
    os.makedirs(folder)
    rel = local is not None or long is not None
    run = {"log": log, "config": CONFIG, "mode": mode, "repeat": repeat, "seed": None,
           "skip_scans": repeat, "local": local, "long": long,
           "all": None if not rel else (local or 0) + (long or 0), "ate": ate, "drop": 50.0,
           "cpu": cpu, "cpu_ms_per_scan": cpu, "scans_in": 1000, "scans_kept": 500,
           "icp_rejected": 7 * repeat, "lost_tracks": repeat % 2, "finished": True, "command": command(relations=rel, gt=ate is not None)}
    run.update(more)
    with open(os.path.join(folder, "run.json"), "w") as f:
        json.dump(run, f)


def write_crash(out, log, mode, repeat, relations=True, gt=False):
    """The run.json run_job writes when kfd-icp-slam fails."""
    folder = run_path(out, log, mode, repeat)
    os.makedirs(folder)
    with open(os.path.join(folder, "run.json"), "w") as f:
        json.dump({"log": log, "config": CONFIG, "mode": mode, "repeat": repeat, "seed": None,
                   "skip_scans": repeat, "finished": False, "exit_code": 1,
                   "error": "kfd-icp-slam failed (exit 1): boom",
                   "command": command(relations, gt)}, f)


def write_stopped(out, log, mode, repeat):
    """A job that stopped: its rKK.stderr is left and there is no run.json."""
    folder = run_path(out, log, mode, repeat)
    os.makedirs(os.path.dirname(folder), exist_ok=True)
    open(folder + ".stderr", "w").close()


def read(*path):
    with open(os.path.join(*path)) as f:
        return f.read()


def section(text, title):
    """The part of a markdown file under '## title', up to the next '## '."""
    start = text.index("## " + title + "\n")
    end = text.find("\n## ", start + 1)
    return text[start:end if end >= 0 else len(text)]


def find_row(text, first_cells):
    """The line of the one table row that starts with these cells."""
    prefix = "| " + " | ".join(first_cells) + " |"
    rows = [line for line in text.splitlines() if line.startswith(prefix)]
    assert len(rows) == 1, (prefix, rows)
    return rows[0]


def table_row(text, first_cells):
    """The cells of the table row that starts with these cells."""
    return [c.strip() for c in find_row(text, first_cells).strip("|").split("|")]


def reason(text, first_cells, column):
    """A '–' cell of a table row and the reason the legend under its table gives for it."""
    row = find_row(text, first_cells)
    cell = table_row(text, first_cells)[column]
    assert re.fullmatch("–[¹²³⁴⁵⁶⁷⁸⁹]+", cell), (row, cell)
    below = text[text.index(row):].split("\n\n")  # the table, then its legend
    m = re.search(r"^- %s (.*)$" % re.escape(cell), below[1], re.M)
    assert m, (cell, below[:2])
    return m.group(1)


class Base(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="kfd_report_test_")
        self.out = os.path.join(self.tmp, "out")

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def collect(self, **kw):
        stats = kfd_compare.collect(self.out, plots=False, quiet=True, **kw)
        self.report, self.summary = read(self.out, "report.md"), read(self.out, "summary.md")
        for text in (self.report, self.summary):  # no "–" cell without its footnote marker
            for line in text.splitlines():
                if line.startswith("|"):
                    self.assertNotIn("–", [c.strip() for c in line.strip("|").split("|")], line)
        return stats

    def verdict(self, stats, log, a, b):
        found = [v for v in stats["verdicts"] if (v["log"], v["a"], v["b"]) == (log, a, b)]
        self.assertEqual(len(found), 1)
        return found[0]


class FewRuns(Base):
    """aces, 5 repeats: kfd with two long errors far above none's; keyframe with a crashed run
    and a job that stopped."""

    def setUp(self):
        super().setUp()
        for k in range(5):
            write_run(self.out, "aces", "none", k, local=0.10 + 0.01 * k, long=NONE_LONG[k])
            write_run(self.out, "aces", "kfd", k, local=0.11 + 0.01 * k, long=KFD_LONG[k])
            if k == 2:
                write_crash(self.out, "aces", "keyframe", k)
            elif k == 4:
                write_stopped(self.out, "aces", "keyframe", k)
            else:
                write_run(self.out, "aces", "keyframe", k, local=0.10 + 0.01 * k,
                          long=NONE_LONG[k])

    def test_runs_above_f_times_the_baseline_median_and_runs_that_did_not_finish_fail(self):
        stats = self.collect()
        threshold = 3 * kfd_stats.median(NONE_LONG)
        expected_kfd = [k for k, x in enumerate(KFD_LONG) if x > threshold]
        self.assertEqual(expected_kfd, [3, 4])
        runs = {(r["mode"], r["repeat"]): r for r in stats["runs"]}
        self.assertEqual(len(runs), 15)  # the crashed and the stopped run are counted
        self.assertEqual([k for k in range(5) if runs[("kfd", k)]["failed"]], expected_kfd)
        self.assertEqual([k for k in range(5) if runs[("none", k)]["failed"]], [])
        self.assertEqual([k for k in range(5) if runs[("keyframe", k)]["failed"]], [2, 4])
        self.assertIn("did not finish: kfd-icp-slam failed (exit 1): boom",
                      runs[("keyframe", 2)]["failure"])
        self.assertIn("did not finish: no run.json", runs[("keyframe", 4)]["failure"])
        self.assertIn("long error 28.500 m > 3 × none's median 1.300 m",
                      runs[("kfd", 3)]["failure"])
        rows = {r["mode"]: r for r in stats["summary"]}
        self.assertEqual((rows["kfd"]["failed"], rows["kfd"]["n_runs"]), (2, 5))
        self.assertEqual((rows["keyframe"]["failed"], rows["keyframe"]["n_runs"]), (2, 5))
        long = [t for t in stats["failure_thresholds"] if t["metric"] == "long"]
        self.assertEqual(len(long), 1)
        self.assertAlmostEqual(long[0]["threshold"], threshold)
        self.assertEqual(stats["failure_factor"], 3.0)
        aces = section(self.report, "aces, cfg")
        self.assertEqual(table_row(aces, ["kfd", "5"])[2], "2/5")
        self.assertEqual(table_row(aces, ["keyframe", "5"])[2], "2/5")
        self.assertEqual(table_row(aces, ["none", "5"])[2], "0/5")
        self.assertEqual(table_row(self.summary, ["aces", "kfd", "5"])[3], "2/5")
        self.assertIn("F = 3 × the median", self.report)
        self.assertIn("F = 3 × the median", self.summary)
        self.assertIn("- kfd r03 (`runs/aces/cfg/kfd/r03`): long error 28.500 m > 3 × none's "
                      "median 1.300 m", aces)
        with open(os.path.join(self.out, "runs.csv")) as f:
            header = f.readline().strip().split(",")
        self.assertEqual(header[-4:], ["finished", "failed", "failure", "folder"])

    def test_the_failure_factor_is_an_option(self):
        self.assertEqual(kfd_compare.main(["collect", self.out, "-q", "--no-plots",
                                           "--failure-factor", "20"]), 0)
        stats = json.loads(read(self.out, "runs.json"))
        self.assertEqual(stats["failure_factor"], 20.0)
        kfd = [r for r in stats["runs"] if r["mode"] == "kfd" and r["failed"]]
        self.assertEqual([r["repeat"] for r in kfd], [3])  # 28.5 > 26, 15.8 < 26
        self.assertIn("F = 20 × the median", read(self.out, "summary.md"))

    def test_the_worst_run_has_the_largest_long_error(self):
        stats = self.collect()
        worst = {w["mode"]: w for w in stats["worst"]}
        k = KFD_LONG.index(max(KFD_LONG))
        self.assertEqual((worst["kfd"]["repeat"], worst["kfd"]["by"]), (k, "long"))
        self.assertEqual(worst["kfd"]["folder"], "runs/aces/cfg/kfd/r%02d" % k)
        self.assertEqual(worst["none"]["repeat"], NONE_LONG.index(max(NONE_LONG)))
        aces = section(self.report, "aces, cfg")
        row = table_row(aces, ["kfd", "r%02d" % k])
        self.assertEqual(row[2:4], ["%.3f" % (0.11 + 0.01 * k), "28.500"])
        self.assertEqual(row[5], "%d / %d" % (7 * k, k % 2))  # ICP rejected / lost tracks
        self.assertEqual(row[6], "`runs/aces/cfg/kfd/r%02d`" % k)
        self.assertEqual(reason(aces, ["kfd", "r%02d" % k], 4),
                         "no ground-truth trajectory (.gt.tum) for this log")
        self.assertIn("| aces | kfd | long error | r%02d |" % k, self.summary)

    def test_more_failed_runs_than_a_baseline_without_any_is_worse(self):
        stats = self.collect()
        v = self.verdict(stats, "aces", "kfd", "none")
        self.assertEqual((v["verdict"], v["failed_a"], v["failed_b"]), ("WORSE", 2, 0))
        self.assertEqual(v["worse_on"], [])  # n = 5 can show no significant difference
        v = self.verdict(stats, "aces", "keyframe", "none")
        self.assertEqual((v["verdict"], v["failed_a"]), ("WORSE", 2))
        self.assertIn("aces, cfg: kfd vs none — WORSE (local error 0.130 vs 0.120 m, Wilcoxon p = "
                      "0.06; long error 2.72 vs 1.30 m, Wilcoxon p = ", self.summary)
        self.assertIn("; 2 failed runs vs 0) at CPU ratio 1.00 [1.00–1.00]", self.summary)

    def test_five_runs_warn_once_that_nothing_can_be_significant(self):
        stats = self.collect()
        warning = "n = 5: the smallest possible p is %.2g; no difference can be significant" \
            % kfd_stats.smallest_p(5)
        self.assertIn("0.062", warning)
        v = self.verdict(stats, "aces", "kfd", "none")
        self.assertEqual((v["n"], v["small_n"]), (5, True))
        self.assertNotIn("smallest possible p", v["text"])  # said once, below the verdicts
        aces = section(self.report, "aces, cfg")
        self.assertIn("- " + v["text"] + "\n", aces)
        self.assertIn("- " + v["text"] + "\n", self.summary)
        # keyframe's crashed and stopped runs leave 3 pairs
        v = self.verdict(stats, "aces", "keyframe", "none")
        self.assertEqual((v["n"], v["repeats"]), (3, 5))
        for text in (aces, self.summary):
            self.assertEqual(text.count(warning), 1, text)
            self.assertEqual(text.count("n = 3: the smallest possible p is 0.25; no difference "
                                        "can be significant"), 1)
            self.assertIn("**Warning** (kfd vs none on aces): " + warning, text)

    def test_every_dash_has_its_reason(self):
        self.collect()
        aces = section(self.report, "aces, cfg")
        no_gt = "no ground-truth trajectory (.gt.tum) for this log"
        self.assertEqual(reason(aces, ["none", "5"], 7), no_gt)
        self.assertEqual(reason(self.summary, ["aces", "kfd", "5"], 7), no_gt)
        self.assertEqual(reason(self.summary, ["aces", "kfd vs none"], 6), no_gt)


class ManyRuns(Base):
    """intel, 20 repeats: kfd significantly better on local, keyframe significantly worse,
    decimate@kfd no different, odometry@kfd better on local but with more failed runs than
    none (whose own repeat 5 fails against its own median)."""

    def setUp(self):
        super().setUp()
        local = [0.10 + 0.003 * k for k in range(20)]
        long = [1.0 + 0.02 * k for k in range(20)]
        base_long = list(long)
        base_long[5] = 10.0  # above 3 x none's own median
        modes = {"none": (local, base_long),
                 "kfd": ([0.9 * x for x in local], long),
                 "keyframe": ([1.2 * x for x in local], long),
                 "decimate@kfd": ([x + 0.004 * (-1) ** k for k, x in enumerate(local)], long),
                 "odometry@kfd": ([0.9 * x for x in local], [20.0, 20.0] + long[2:])}
        for mode, (lo, ln) in modes.items():
            for k in range(20):
                write_run(self.out, "intel", mode, k, local=lo[k], long=ln[k], cpu=10.0 + k)

    def test_verdicts(self):
        stats = self.collect()
        runs = [r for r in stats["runs"] if r["mode"] == "none" and r["failed"]]
        self.assertEqual([r["repeat"] for r in runs], [5])
        better = self.verdict(stats, "intel", "kfd", "none")
        self.assertEqual((better["verdict"], better["better_on"], better["worse_on"]),
                         ("BETTER", ["local"], []))
        self.assertEqual((better["failed_a"], better["failed_b"]), (0, 1))
        worse = self.verdict(stats, "intel", "keyframe", "none")
        self.assertEqual((worse["verdict"], worse["worse_on"]), ("WORSE", ["local"]))
        same = self.verdict(stats, "intel", "decimate@kfd", "none")
        self.assertEqual((same["verdict"], same["better_on"], same["worse_on"]),
                         ("NO SIGNIFICANT DIFFERENCE", [], []))
        failing = self.verdict(stats, "intel", "odometry@kfd", "none")
        self.assertEqual((failing["better_on"], failing["failed_a"], failing["failed_b"]),
                         (["local"], 2, 1))
        self.assertEqual(failing["verdict"], "NO SIGNIFICANT DIFFERENCE")
        line = "- intel, cfg: keyframe vs none — WORSE (local error "
        self.assertIn(line, self.report)
        self.assertIn(line, self.summary)
        self.assertIn("at CPU ratio 1.00 [1.00–1.00]", better["text"])
        self.assertIn("intel, cfg: kfd vs none — BETTER (", self.summary)

    def test_twenty_runs_give_no_small_sample_warning(self):
        stats = self.collect()
        self.assertLess(kfd_stats.smallest_p(20), 0.05)
        self.assertTrue(all(not v["small_n"] and v["n"] == 20 for v in stats["verdicts"]))
        self.assertNotIn("smallest possible p", self.report)
        self.assertNotIn("smallest possible p", self.summary)


class DashReasons(Base):
    """A simulated log (ground truth, no relations) where every run of one mode crashed."""

    def setUp(self):
        super().setUp()
        for k in range(3):
            write_run(self.out, "sim", "none", k, ate=0.010 + 0.001 * k)
            write_run(self.out, "sim", "kfd", k, ate=0.012 + 0.001 * k)
            write_crash(self.out, "sim", "keyframe", k, relations=False, gt=True)

    def test_reasons(self):
        stats = self.collect()
        sim = section(self.report, "sim, cfg")
        self.assertEqual(reason(sim, ["kfd", "3"], 4), "no relations file for this log")
        self.assertEqual(table_row(sim, ["kfd", "3"])[7], "0.013 [0.013–0.014]")  # ATE
        self.assertEqual(table_row(sim, ["keyframe", "3"])[2], "3/3")
        self.assertEqual(reason(sim, ["keyframe", "3"], 7), "no run of keyframe finished")
        worst = sim[sim.index("Worst run"):]  # ranked by ATE here
        self.assertEqual(reason(worst, ["keyframe"], 1), "no run of keyframe finished")
        self.assertEqual(self.verdict(stats, "sim", "kfd", "none")["verdict"],
                         "NO SIGNIFICANT DIFFERENCE")
        self.assertIn("sim, cfg: kfd vs none — NO SIGNIFICANT DIFFERENCE (ATE 0.0130 vs 0.0110 m",
                      self.summary)
        v = self.verdict(stats, "sim", "keyframe", "none")
        self.assertEqual((v["verdict"], v["failed_a"]), ("WORSE", 3))
        self.assertIn("ATE: no run of keyframe finished", v["text"])
        self.assertIn("CPU ratio unknown (no run of keyframe finished)", v["text"])
        self.assertEqual(reason(self.summary, ["sim", "keyframe vs none"], 6),
                         "no run of keyframe finished")
        self.assertEqual(reason(self.summary, ["sim", "keyframe vs none"], 3),
                         "no relations file for this log")
        self.assertEqual(reason(self.summary, ["sim", "keyframe", "3"], 5),
                         "no relations file for this log")
        self.assertEqual(reason(self.summary, ["sim", "kfd vs none"], 3),
                         "no relations file for this log")


def write_trajectory(out, log, mode, repeat, poses):
    with open(os.path.join(run_path(out, log, mode, repeat), "trajectory.tum"), "w") as f:
        f.write("# timestamp x y z qx qy qz qw\n")
        for t, x, y, yaw in poses:
            f.write("%.6f %.6f %.6f 0 0 0 %.9f %.9f\n" % (t, x, y, math.sin(yaw / 2),
                                                         math.cos(yaw / 2)))


def path(noise, seed, bend=0.0):
    """A 30 m walk (0.1 m steps, a turn halfway), each pose moved by Gaussian noise of `noise`
    m; bend (rad per step) turns every step a little more (a drifting estimate)."""
    rng = random.Random(seed)
    poses, x, y, yaw = [], 0.0, 0.0, 0.0
    for i in range(300):
        poses.append((0.2 * i, x + rng.gauss(0, noise), y + rng.gauss(0, noise), yaw))
        yaw += (0.01 if 100 <= i < 200 else 0.0) + bend
        x, y = x + 0.1 * math.cos(yaw), y + 0.1 * math.sin(yaw)
    return poses


class NoGroundTruth(Base):
    """A log without relations or ground truth, 6 repeats: kfd's trajectories differ from none's
    as much as none's differ from each other; keyframe's drift. The config runs ICP on every
    scan."""

    def setUp(self):
        super().setUp()
        config = os.path.join(self.tmp, CONFIG + ".ini")
        with open(config, "w") as f:
            f.write("[MappingApplication]\nlocalizationLinDistance = 0\n"
                    "localizationAngDistance = 0 # every scan\n")
        for k in range(6):
            for i, (mode, noise, bend, cpu) in enumerate((
                    ("none", 0.01, 0.0, 10.0), ("kfd", 0.01, 0.0, 5.0),
                    ("keyframe", 0.01, 0.002, 4.0))):
                write_run(self.out, "mine", mode, k, cpu=cpu + 0.1 * k, lost_tracks=0,
                          command=["kfd-icp-slam", config, "mine.bag", "-m", mode])
                write_trajectory(self.out, "mine", mode, k,
                                 path(noise, 10 * k + i, bend)[k:])

    def test_a_mode_is_judged_against_the_baselines_own_spread(self):
        stats = self.collect()
        within = self.verdict(stats, "mine", "kfd", "none")
        self.assertTrue(within["verdict"].startswith("WITHIN NONE'S SPREAD ("), within["verdict"])
        self.assertFalse(within["small_n"])  # the rank-sum test can be significant with 6 runs
        beyond = self.verdict(stats, "mine", "keyframe", "none")
        self.assertTrue(beyond["verdict"].startswith("BEYOND NONE'S SPREAD ("))
        self.assertLess(beyond["spread"]["ate"]["p"], 0.05)
        self.assertEqual(beyond["spread"]["beyond"], 6)
        self.assertIn("mine, cfg: kfd vs none — WITHIN NONE'S SPREAD", self.summary)
        self.assertIn("no ground truth: kfd's trajectory vs none's of the same repeat: ATE ",
                      within["text"])
        self.assertIn("ICP rejected 17.5 vs 17.5; lost tracks 0 vs 0 (medians)", within["text"])
        self.assertTrue(within["text"].endswith(") at CPU ratio 0.51 [0.50–0.52], ICP on every "
                                                "scan"), within["text"])
        self.assertNotIn("smallest possible p", self.summary)

    def test_without_trajectories_nothing_is_judged(self):
        for k in range(6):
            os.remove(os.path.join(run_path(self.out, "mine", "none", k), "trajectory.tum"))
        stats = self.collect()
        v = self.verdict(stats, "mine", "kfd", "none")
        self.assertEqual(v["verdict"], "CANNOT JUDGE")
        self.assertIn("no two finished none runs with a trajectory", v["text"])


def standing(noise, seed, n=200):
    """A sensor standing still at (3, -2), heading 0.5 rad: ICP's jitter of `noise` m."""
    rng = random.Random(seed)
    return [(0.2 * i, 3 + rng.gauss(0, noise), -2 + rng.gauss(0, noise), 0.5 + rng.gauss(0, 0.002))
            for i in range(n)]


class StillSensor(Base):
    """A log without ground truth whose sensor stands still, 6 repeats: there the one true pose
    makes each run's scatter its error. kfd scatters less than none, keyframe more; drift is
    not measured on jitter."""

    def setUp(self):
        super().setUp()
        for k in range(6):
            for i, (mode, noise) in enumerate((("none", 0.006), ("kfd", 0.002),
                                               ("keyframe", 0.02))):
                write_run(self.out, "still", mode, k, cpu=5.0, lost_tracks=0,
                          command=["kfd-icp-slam", CONFIG + ".ini", "still.bag", "-m", mode])
                write_trajectory(self.out, "still", mode, k, standing(noise, 10 * k + i)[k:])

    def test_each_runs_scatter_is_its_error(self):
        stats = self.collect()
        v = self.verdict(stats, "still", "kfd", "none")
        self.assertTrue(v["verdict"].startswith("SCATTERS NO MORE THAN NONE ("), v["verdict"])
        self.assertIn("the sensor stands still", v["text"])
        self.assertLess(v["spread"]["scatter"]["mode"], v["spread"]["scatter"]["baseline"])
        worse = self.verdict(stats, "still", "keyframe", "none")
        self.assertTrue(worse["verdict"].startswith("SCATTERS MORE THAN NONE ("), worse["verdict"])
        self.assertLess(worse["spread"]["scatter"]["p"], 0.05)

    def test_jitter_is_no_path_for_drift(self):
        pairs = kfd_agreement.match(standing(0.01, 1), standing(0.01, 2), 1e-3)
        self.assertIsNone(kfd_agreement.drift_per_m(pairs))
        moving = kfd_agreement.match(path(0.01, 1), path(0.01, 2), 1e-3)
        self.assertIsNotNone(kfd_agreement.drift_per_m(moving))


class BeforeRunning(unittest.TestCase):
    SHARE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "share",
                         "kfd-icp-slam")

    def test_each_log_says_what_its_verdict_rests_on(self):
        with tempfile.TemporaryDirectory() as tmp:
            bag = os.path.join(tmp, "mine.bag")
            open(bag, "w").close()
            log = kfd_compare.resolve_log(bag, tmp)
            self.assertIn("mine: no ground truth (no .relations or .gt.tum beside it): accuracy "
                          "is judged against none's own spread",
                          kfd_compare.what_is_judged(log, ["none", "kfd"], "none"))
            self.assertIn("no verdict on accuracy (add mode none)",
                          kfd_compare.what_is_judged(log, ["kfd"], "none"))
            open(os.path.join(tmp, "mine.relations"), "w").close()
            self.assertIn("relations mine.relations: judged on the local and long relations error",
                          kfd_compare.what_is_judged(kfd_compare.resolve_log(bag, tmp), ["kfd"],
                                                     "none"))

    def test_one_flag_runs_both_icp_schedules_and_each_is_named(self):
        gated = os.path.join(self.SHARE, "sick-180-5hz.ini")
        every = os.path.join(self.SHARE, "sick-180-5hz-every-scan.ini")
        a = argparse.Namespace(configs=[gated], icp="both")
        self.assertEqual(kfd_compare.icp_configs(a), [gated, every])
        a.icp = "every-scan"
        self.assertEqual(kfd_compare.icp_configs(a), [every])
        a.configs, a.icp = [every], "gated"
        self.assertEqual(kfd_compare.icp_configs(a), [gated])
        self.assertEqual(kfd_report.icp_schedule([{"command": ["x", gated]}]),
                         "ICP after 0.2 m / 5° of odometry")
        self.assertEqual(kfd_report.icp_schedule([{"command": ["x", every]}]), "ICP on every scan")
        with tempfile.TemporaryDirectory() as tmp:
            lone = os.path.join(tmp, "lone.ini")
            open(lone, "w").close()
            a.configs, a.icp = [lone], "both"
            with self.assertRaises(kfd_compare.CompareError) as e:
                kfd_compare.icp_configs(a)
            self.assertIn("--icp both: no %s-every-scan.ini beside" % lone[:-4], str(e.exception))


FAIL = "#!/bin/sh\necho 'no usable scan in the log' >&2\nexit 1\n"
# kfd-icp-slam's arguments: CONFIG LOG -o FOLDER ...; a summary.json with what run_job reads
SUCCEED = ("#!/bin/sh\nmkdir -p \"$4\"\necho '{\"dropped_pct\": 10.0, \"scans_in\": 100, "
           "\"scans_kept\": 90}' > \"$4/summary.json\"\n")


class NothingToCompare(Base):
    """Runs of one mode only: the report says why there is no verdict, in the user's words."""

    def test_the_baseline_alone_asks_for_another_mode(self):
        for k in range(3):
            write_run(self.out, "aces", "kfd", k, local=0.1, long=1.0)
        self.collect(baseline="kfd")
        self.assertIn("No pair to judge: `kfd` (the baseline) is the only mode run", self.report)

    def test_no_baseline_runs_says_so(self):
        for k in range(3):
            write_run(self.out, "aces", "kfd", k, local=0.1, long=1.0)
        self.collect(baseline="none")
        self.assertIn("No pair to judge: no `none` runs (the baseline)", self.report)


class RunJob(Base):
    def job(self, script):
        exe = os.path.join(self.tmp, "kfd-icp-slam")
        with open(exe, "w") as f:
            f.write(script)
        os.chmod(exe, os.stat(exe).st_mode | stat.S_IXUSR)
        log = os.path.join(self.tmp, "x.rawlog")
        open(log, "w").close()
        return argparse.Namespace(out=self.out, log=log, datasets=self.tmp, config=CONFIG + ".ini",
                                  mode="kfd", repeat=0, exe=exe, sim_exe="kfd-simulate",
                                  split_seconds=10.0, map=False, scan_topic=None,
                                  odom_topic=None)

    def test_a_failed_run_is_recorded_counted_and_run_again_on_resume(self):
        with self.assertRaises(kfd_compare.CompareError) as e:
            kfd_compare.run_job(self.job(FAIL))
        self.assertIn("kfd-icp-slam failed (exit 1): no usable scan in the log", str(e.exception))
        stats = self.collect()
        self.assertEqual(len(stats["runs"]), 1)
        r = stats["runs"][0]
        self.assertEqual((r["finished"], r["failed"], r["exit_code"]), (False, True, 1))
        self.assertEqual(r["failure"],
                         "did not finish: kfd-icp-slam failed (exit 1): no usable scan in the log")
        self.assertEqual(table_row(section(self.report, "x, cfg"), ["kfd", "1"])[2], "1/1")
        run = kfd_compare.run_job(self.job(SUCCEED))  # resume runs it again
        self.assertTrue(run["finished"])
        self.assertEqual(run["scans_kept"], 90)
        self.assertFalse(os.path.exists(run_path(self.out, "x", "kfd", 0) + ".stderr"))
        stats = self.collect()
        self.assertEqual([r["failed"] for r in stats["runs"]], [False])


if __name__ == "__main__":
    unittest.main()
