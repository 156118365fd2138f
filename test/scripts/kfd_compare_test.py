"""kfd-compare end to end: a small run (2 logs x 2 modes x 3 repeats) through the real
kfd-icp-slam, and the emitted job list run through GNU parallel, then collected.
Usage: kfd_compare_test.py BUILD_APPS_DIR DATASETS_DIR"""
import csv
import glob
import gzip
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
COMPARE = os.path.join(ROOT, "scripts", "kfd-compare")
OFFICE = os.path.join(ROOT, "rawlogs", "office-mit-0.752.rawlog")
APPS = DATASETS = None


def compare(*args):
    return subprocess.run([COMPARE] + list(args), capture_output=True, text=True)


class KfdCompare(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="kfd_compare_test_")
        self.exe = ["--exe", os.path.join(APPS, "kfd-icp-slam"),
                    "--sim-exe", os.path.join(APPS, "kfd-simulate"), "--datasets", DATASETS]

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def fake_runs(self, out, config, mode, local):
        """Finished runs of `mode` under `config` on log L, one per value of `local`."""
        for k, v in enumerate(local):
            d = os.path.join(out, "runs", "L", config, mode, "r%02d" % k)
            os.makedirs(d)
            with open(os.path.join(d, "run.json"), "w") as f:
                json.dump({"log": "L", "config": config, "mode": mode, "repeat": k,
                           "finished": True, "local": v, "long": 2 * v, "all": 3 * v,
                           "cpu": 10.0 + k}, f)

    def test_configs_pairs_one_mode_under_two_configs_by_repeat(self):
        out = os.path.join(self.tmp, "out")
        # Under A the local error is lower on 7 of 8 repeats; the repeats pair up by number.
        a = [0.10, 0.11, 0.09, 0.12, 0.10, 0.08, 0.13, 0.30]
        b = [0.20, 0.21, 0.19, 0.22, 0.20, 0.18, 0.23, 0.10]
        self.fake_runs(out, "cfgA", "kfd", a)
        self.fake_runs(out, "cfgB", "kfd", b)
        self.fake_runs(out, "cfgB", "none", b)  # another mode: not in the table
        r = compare("configs", out, "--mode", "kfd", "--configs", "share/x/cfgA.ini", "cfgB.ini")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = {line.split("|")[2].strip(): line for line in r.stdout.splitlines()
                if line.startswith("| L |")}
        self.assertEqual(set(rows), {"local", "long", "all", "cpu"})
        # 7 wins, 1 loss: two-sided exact sign test p = 18/256 = 0.0703
        self.assertIn("| 8 | 0.105 | 0.200 | 7/1 (0.07) |", rows["local"])
        self.assertIn("| 0/0 (1) |", rows["cpu"])  # the same CPU times: all ties
        self.assertEqual(open(os.path.join(out, "configs.md")).read(), r.stdout)
        bad = compare("configs", out, "--mode", "kfd", "--configs", "cfgA", "cfgC")
        self.assertEqual(bad.returncode, 1)
        self.assertIn("no log has finished 'kfd' runs under both cfgA and cfgC", bad.stderr)

    def test_curve_pairs_every_config_with_one_reference_run(self):
        out = os.path.join(self.tmp, "out")
        ini = {}
        for name, vc in (("ref", "0.75"), ("lo", "0.40"), ("hi", "1.20")):
            ini[name] = os.path.join(self.tmp, name + ".ini")
            # A later key wins; comments are cut; the stage's section, or a flat key of before
            # ("hi"); another section's key of the same name is not it.
            section = "[KFD]" if name == "hi" else "[KFD]\n[KFD.view_keyframe]"
            with open(ini[name], "w") as f:
                f.write("[ICP]\nmax_view_change = 9\n%s\nmax_view_change = 0.5\n"
                        "max_view_change = %s   # the knob\n[KFD.other]\nmax_view_change_x = 3\n"
                        % (section, vc))

        def runs(config, mode, local, drop, cpu, finished=True):
            for k, v in enumerate(local):
                d = os.path.join(out, "runs", "L", config, mode, "r%02d" % k)
                os.makedirs(d)
                run = {"log": "L", "config": config, "mode": mode, "repeat": k,
                       "finished": True, "local": v, "long": 2 * v, "drop": drop, "cpu": cpu,
                       "command": ["kfd-icp-slam", ini[config], "L.rawlog"]}
                if not finished and k == 0:
                    run = {"log": "L", "config": config, "mode": mode, "repeat": k,
                           "finished": False, "error": "killed"}
                with open(os.path.join(d, "run.json"), "w") as f:
                    json.dump(run, f)

        none = [0.10] * 8
        runs("ref", "none", none, 0.0, 10.0)
        runs("ref", "kfd", [0.12] * 7 + [0.08], 60.0, 5.0)  # 1 win, 7 losses
        runs("lo", "kfd", [0.10] * 6 + [0.09, 0.50], 30.0, 8.0)  # r07: 5 x none's median
        runs("hi", "kfd", [0.20] * 4, 80.0, 2.0, finished=False)  # r00 did not finish
        runs("ref", "odometry@kfd", [0.3] * 8, 60.0, 5.0)  # another mode: not a row
        r = compare("curve", out, "--reference", "none@ref.ini", "--key", "max_view_change")
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = [line for line in r.stdout.splitlines() if line.startswith("| ")]
        self.assertIn("| config | max_view_change | n | failed | dropped % | local error (m) | "
                      "ratio | W/L (p) | long error (m) | ratio | W/L (p) | CPU ratio | "
                      "worst run |", rows[0])
        # none's row first (its mode ignores [KFD]), then the configs by name, paired by repeat
        self.assertEqual(rows[1], "| none (ref) | – | 8 | 0/8 | 0.0 | 0.100 |  |  | 0.200 |  "
                         "|  |  | r00 0.200 m |")
        self.assertEqual(rows[2].split(" | ")[:8], ["| hi", "1.20", "4", "1/4", "80.0",
                                                    "0.200", "2.00", "0/3 (0.25)"])
        lo = rows[3].split(" | ")
        self.assertEqual(lo[:8], ["| lo", "0.40", "8", "1/8", "30.0", "0.100", "1.00",
                                  "1/1 (1.00)"])  # six ties
        self.assertEqual(lo[-2:], ["0.80", "r07 1.000 m |"])
        ref = rows[4].split(" | ")
        self.assertEqual(ref[:8], ["| ref", "0.75", "8", "0/8", "60.0", "0.120", "1.20",
                                   "1/7 (0.07)"])
        self.assertEqual(ref[-2], "0.50")
        self.assertEqual(open(os.path.join(out, "curve.md")).read(), r.stdout)
        bad = compare("curve", out, "--reference", "none@other")
        self.assertEqual(bad.returncode, 1)
        self.assertIn("no 'none' runs under other", bad.stderr)
        bad = compare("curve", out, "--reference", "none")
        self.assertEqual(bad.returncode, 1)
        self.assertIn("--reference is MODE@CONFIG", bad.stderr)

    def test_small_run_reports_every_log_mode_and_pair(self):
        csail = os.path.join(DATASETS, "mit-csail", "mit-csail.rawlog")
        if not os.path.exists(csail):
            self.skipTest("missing " + csail)
        out = os.path.join(self.tmp, "out")
        r = compare("run", "--logs", OFFICE, "mit-csail", "--modes", "none", "kfd",
                    "--repeats", "3", "--jobs", "2", "--out", out, "-q", *self.exe)
        self.assertEqual(r.returncode, 0, r.stderr)
        stats = json.load(open(os.path.join(out, "runs.json")))
        runs = stats["runs"]
        self.assertEqual(len(runs), 12)
        # repeat K skips the first K scans: one scan fewer per repeat
        office = sorted((x for x in runs if x["log"] == "office-mit-0.752" and
                         x["mode"] == "none"), key=lambda x: x["repeat"])
        self.assertEqual([x["scans_in"] for x in office], [600, 599, 598])
        for x in runs:
            self.assertGreater(x["cpu"], 0.0)
            if x["log"] == "mit-csail":  # relations split into local and long
                self.assertGreater(x["relations_local_used"], 0)
                self.assertGreater(x["relations_long_used"], 0)
                self.assertIsNone(x["ate"])
            else:  # ground truth trajectory, no relations
                self.assertIsNone(x["local"])
                self.assertGreater(x["ate"], 0.0)
        pairs = {(p["log"], p["a"], p["b"], p["metric"]): p for p in stats["pairs"]}
        p = pairs[("mit-csail", "kfd", "none", "local")]
        self.assertEqual(p["n"], 3)
        self.assertEqual(p["wins"] + p["losses"] + p["ties"], 3)
        self.assertIn(("office-mit-0.752", "kfd", "none", "ate"), pairs)
        report = open(os.path.join(out, "report.md")).read()
        self.assertIn("## mit-csail, sick-180-5hz", report)
        self.assertIn("| kfd vs none | local | 3 |", report)
        for log in ("mit-csail", "office-mit-0.752"):
            self.assertTrue(os.path.getsize(os.path.join(out, "plots",
                                                         log + "-sick-180-5hz.png")) > 1000)
        header = open(os.path.join(out, "runs.csv")).readline()
        self.assertTrue(header.startswith("log,config,mode,repeat,seed,skip_scans,local,long"))

    def test_emitted_jobs_run_through_gnu_parallel_give_the_same_runs(self):
        if not shutil.which("parallel"):
            self.skipTest("GNU parallel not installed")
        modes = ["none", "decimate@kfd"]
        local = os.path.join(self.tmp, "local")
        r = compare("run", "--logs", OFFICE, "--modes", *modes, "--repeats", "2", "--jobs", "2",
                    "--out", local, "-q", "--no-plots", *self.exe)
        self.assertEqual(r.returncode, 0, r.stderr)
        farm = os.path.join(self.tmp, "farm")
        jobs = os.path.join(self.tmp, "jobs.txt")
        r = compare("run", "--logs", OFFICE, "--modes", *modes, "--repeats", "2", "--out", farm,
                    "--emit-jobs", jobs, *self.exe)
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = open(jobs).read().splitlines()
        self.assertEqual(len(lines), 4)
        with open(jobs) as f:
            p = subprocess.run(["parallel", "--will-cite", "-j", "2", "--halt", "now,fail=1"],
                               stdin=f, capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        r = compare("collect", farm, "-q", "--no-plots")
        self.assertEqual(r.returncode, 0, r.stderr)
        a = json.load(open(os.path.join(local, "runs.json")))["runs"]
        b = json.load(open(os.path.join(farm, "runs.json")))["runs"]
        key = lambda x: (x["mode"], x["repeat"])  # noqa: E731
        self.assertEqual([key(x) for x in a], [key(x) for x in b])
        for x, y in zip(a, b):  # the same deterministic runs (CPU times aside)
            self.assertEqual((x["ate"], x["drop"], x["scans_kept"]),
                             (y["ate"], y["drop"], y["scans_kept"]))
        dec = [x for x in b if x["mode"] == "decimate@kfd"]
        self.assertTrue(all(x["target_drop_pct"] > 0 for x in dec))
        self.assertTrue(all(abs(x["drop"] - x["target_drop_pct"]) < 0.5 for x in dec))

    def test_bags_and_carmen_logs_find_their_relations(self):
        from kfd_tools import compare as kfd_compare
        for rel in ("aces/aces.orig.bag", "mit-csail/mit-csail.clf", "intel/intel.reconstructed.clf.gz"):
            path = os.path.join(DATASETS, rel)
            if not os.path.isfile(path):
                continue
            log = kfd_compare.resolve_log(path, DATASETS)
            folder = rel.split("/")[0]
            self.assertEqual(log["relations"],
                             os.path.abspath(os.path.join(DATASETS, folder, folder + ".relations")))
        self.assertEqual(kfd_compare.log_stem("aces.orig.bag"), "aces.orig")
        self.assertEqual(kfd_compare.log_stem("intel.clf.gz"), "intel")
        self.assertEqual(kfd_compare.log_stem("run.mcap"), "run")
        # A ROS 2 bag: a rosbag2 folder is a log named after the folder.
        ros2 = os.path.join(DATASETS, "mumble-rplidar-ros2", "straight")
        if os.path.isdir(ros2):
            log = kfd_compare.resolve_log(ros2 + os.sep, DATASETS)
            self.assertEqual((log["name"], log["kind"]), ("straight", "file"))
            out = os.path.join(self.tmp, "ros2")
            r = compare("run", "--logs", ros2, "--modes", "none", "kfd", "--repeats", "1",
                        "--out", out, "--no-plots", "-q", *self.exe)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(os.path.join(out, "runs.csv")) as f:
                runs = list(csv.DictReader(f))
            self.assertEqual(len(runs), 2)
            self.assertTrue(all(x["finished"] == "True" for x in runs))
        # A laser-only bag through kfd-icp-slam, the topic passed on (also to emitted jobs).
        bag = os.path.join(DATASETS, "ccny-urg", "demo.bag")
        if not os.path.isfile(bag):
            return
        out = os.path.join(self.tmp, "bag")
        r = compare("run", "--logs", bag, "--modes", "none", "kfd", "--repeats", "2", "--out",
                    out, "--scan-topic", "/scan", "--no-plots", "-q", *self.exe)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "runs.csv")) as f:
            runs = list(csv.DictReader(f))
        self.assertEqual(len(runs), 4)
        self.assertEqual(sorted(int(x["scans_in"]) for x in runs), [359, 359, 360, 360])
        jobs = os.path.join(self.tmp, "jobs.txt")
        r = compare("run", "--logs", bag, "--modes", "kfd", "--repeats", "1", "--out", out + "2",
                    "--scan-topic", "/scan", "--emit-jobs", jobs, *self.exe)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("--scan-topic /scan", open(jobs).read())

    def test_a_run_is_reused_only_on_the_same_command_and_inputs(self):
        """Issue 38: an edited config reruns (it kept the old result before); an unchanged one
        is reused."""
        config = os.path.join(self.tmp, "c.ini")
        shutil.copy(os.path.join(ROOT, "share", "kfd-icp-slam", "sick-180-5hz.ini"), config)
        out = os.path.join(self.tmp, "reuse")
        args = ["run", "--logs", OFFICE, "--modes", "kfd", "--repeats", "1", "--out", out,
                "--configs", config, "-q", "--no-plots"] + self.exe
        r = compare(*args)
        self.assertEqual(r.returncode, 0, r.stderr)
        run_json = os.path.join(out, "runs", "office-mit-0.752", "c", "kfd", "r00", "run.json")
        first = json.load(open(run_json))
        self.assertIn(config, first["inputs"])
        r = compare(*args)  # unchanged: reused, not rerun
        self.assertNotIn("running it again", r.stderr)
        self.assertEqual(json.load(open(run_json))["wall_s"], first["wall_s"])
        with open(config, "a") as f:
            f.write("\n# an edit the run must see (any edit reruns)\n")
        r = compare(*args)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("changed: running it again", r.stderr)
        again = json.load(open(run_json))
        self.assertNotEqual(again["inputs"][config]["sha256"], first["inputs"][config]["sha256"])

    def test_runs_that_would_share_a_folder_or_exceed_bounds_are_refused(self):
        out = os.path.join(self.tmp, "tags")
        a, b = os.path.join(self.tmp, "a"), os.path.join(self.tmp, "b")
        for d in (a, b):
            os.makedirs(d)
            shutil.copy(os.path.join(ROOT, "share", "kfd-icp-slam", "sick-180-5hz.ini"), d)
        r = compare("run", "--logs", OFFICE, "--out", out, "--configs",
                    os.path.join(a, "sick-180-5hz.ini"), os.path.join(b, "sick-180-5hz.ini"),
                    *self.exe)
        self.assertEqual(r.returncode, 1)
        self.assertIn("two configs share the name sick-180-5hz", r.stderr)
        copy = os.path.join(a, os.path.basename(OFFICE))
        shutil.copy(OFFICE, copy)
        r = compare("run", "--logs", OFFICE, copy, "--out", out, *self.exe)
        self.assertEqual(r.returncode, 1)
        self.assertIn("two logs share the name office-mit-0.752", r.stderr)
        for flag, value, message in (("--jobs", "0", "--jobs must be in [1, 4096], not 0"),
                                     ("--repeats", "10000000",
                                      "--repeats must be in [1, 1000], not 10000000")):
            r = compare("run", "--logs", OFFICE, "--out", out, flag, value, *self.exe)
            self.assertEqual(r.returncode, 1)
            self.assertIn(message, r.stderr)
            self.assertNotIn("Traceback", r.stderr)
        self.assertFalse(os.path.exists(out))

    def test_an_unreadable_run_json_is_a_failed_run_not_a_traceback(self):
        out = os.path.join(self.tmp, "cut")
        self.fake_runs(out, "cfg", "none", [0.1, 0.2])
        open(os.path.join(out, "runs", "L", "cfg", "none", "r01", "run.json"), "w").close()
        r = compare("collect", out, "-q", "--no-plots")
        self.assertEqual(r.returncode, 0, r.stderr)
        runs = json.load(open(os.path.join(out, "runs.json")))["runs"]
        bad = [x for x in runs if x["repeat"] == 1]
        self.assertEqual(len(bad), 1)
        self.assertTrue(bad[0]["failed"])
        self.assertIn("unreadable run.json", bad[0]["failure"])

    def test_emitted_jobs_name_the_log_by_its_absolute_path(self):
        here = os.getcwd()
        try:
            os.chdir(os.path.dirname(OFFICE))
            jobs = os.path.join(self.tmp, "jobs.txt")
            r = compare("run", "--logs", os.path.basename(OFFICE), "--modes", "none",
                        "--repeats", "1", "--out", os.path.join(self.tmp, "emit"),
                        "--emit-jobs", jobs, *self.exe)
        finally:
            os.chdir(here)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("--log " + OFFICE, open(jobs).read())

    def test_ctrl_c_stops_the_queue_and_records_interrupted_runs_apart(self):
        """Issue 38: one Ctrl-C recorded the running jobs as failed and then ran every queued
        one; a later collect counted them as failures. Now the queue stops, the running run is
        recorded as interrupted, collect leaves it out of the verdicts, a rerun completes it."""
        out = os.path.join(self.tmp, "int")
        args = ["run", "--logs", OFFICE, "--modes", "none", "kfd", "--repeats", "3",
                "--jobs", "1", "--out", out, "-q", "--no-plots"] + self.exe
        p = subprocess.Popen([COMPARE] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
        runs = os.path.join(out, "runs", "office-mit-0.752", "sick-180-5hz")
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not glob.glob(os.path.join(runs, "*", "r01.stderr")):
            time.sleep(0.02)  # the second repeat is running: the first one finished
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=60)
        self.assertEqual(p.returncode, 130, err)
        self.assertIn("interrupted", err)
        self.assertNotIn("Traceback", err)
        records = [json.load(open(f)) for f in glob.glob(os.path.join(runs, "*", "r*",
                                                                      "run.json"))]
        stopped = [r for r in records if r.get("interrupted")]
        self.assertEqual(len(stopped), 1, records)
        self.assertFalse(stopped[0]["finished"])
        self.assertEqual(len(records), 3, "the queue went on after Ctrl-C")  # 2 done, 1 stopped
        r = compare("collect", out, "--no-plots")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("(0 failed, 1 interrupted left out)", r.stderr)
        stats = json.load(open(os.path.join(out, "runs.json")))
        self.assertEqual(len(stats["runs"]), 2)
        self.assertEqual(len(stats["interrupted"]), 1)
        self.assertIn("1 interrupted run(s) left out", open(os.path.join(out, "summary.md")).read())
        r = compare(*args)  # the same command again completes the interrupted and queued runs
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(len(json.load(open(os.path.join(out, "runs.json")))["runs"]), 6)

    def test_collect_writes_its_files_complete_or_not_at_all(self):
        """Issue 38: a full disk left runs.csv cut at 4 096 bytes beside the old summary. Here
        report.md cannot be written (its temporary path is a folder): every old file stays as
        it was and no temporary file is left."""
        out = os.path.join(self.tmp, "atomic")
        self.fake_runs(out, "cfg", "none", [0.1, 0.2, 0.3])
        r = compare("collect", out, "-q", "--no-plots")
        self.assertEqual(r.returncode, 0, r.stderr)
        names = ("runs.csv", "runs.json", "summary.md", "report.md")
        before = {n: open(os.path.join(out, n)).read() for n in names}
        self.fake_runs(out, "cfg", "kfd", [0.1, 0.1, 0.1])
        os.makedirs(os.path.join(out, "report.md.tmp"))
        r = compare("collect", out, "-q", "--no-plots")
        self.assertEqual(r.returncode, 1)
        self.assertIn("cannot write", r.stderr)
        self.assertIn("left as they were", r.stderr)
        self.assertEqual({n: open(os.path.join(out, n)).read() for n in names}, before)
        self.assertEqual(sorted(f for f in os.listdir(out) if f.endswith(".tmp")),
                         ["report.md.tmp"])

    def test_repeats_beyond_the_logs_scans_are_refused_not_failed_runs(self):
        """Issue 38: repeat K skips K scans; on a log of 3 scans, repeats 3 and 4 of 5 were
        counted as failed runs of the method. Now they are an error naming the cause, and the
        runs that exist are judged without a failure."""
        with gzip.open(os.path.join(DATASETS, "aces", "aces.reconstructed.clf.gz"), "rt") as f:
            lines = [x for x in f if x.startswith(("FLASER", "ODOM"))][:6]
        log = os.path.join(self.tmp, "tiny.clf")
        with open(log, "w") as f:
            f.writelines(lines)
        out = os.path.join(self.tmp, "tiny")
        r = compare("run", "--logs", log, "--modes", "none", "--repeats", "5", "--out", out,
                    "-q", "--no-plots", *self.exe)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("--repeats 4 asks for more repeats than the log has scans", r.stderr)
        runs = json.load(open(os.path.join(out, "runs.json")))["runs"]
        self.assertEqual(sorted(x["repeat"] for x in runs), [0, 1, 2])
        self.assertFalse(any(x["failed"] for x in runs))

    def test_bad_input_is_a_clear_error(self):
        out = os.path.join(self.tmp, "bad")
        r = compare("run", "--logs", "no-such-log", "--out", out, "--repeats", "1", *self.exe)
        self.assertEqual(r.returncode, 1)
        self.assertIn("kfd-compare: log not found: no-such-log", r.stderr)
        r = compare("run", "--logs", OFFICE, "--modes", "kfd@none", "--out", out, *self.exe)
        self.assertEqual(r.returncode, 1)
        self.assertIn("only odometry and decimate can match", r.stderr)
        r = compare("run", "--logs", OFFICE, "--modes", "nosuch", "--out", out, *self.exe)
        self.assertEqual(r.returncode, 1)
        self.assertIn("unknown mode 'nosuch'", r.stderr)
        r = compare("collect", os.path.join(self.tmp, "empty"))
        self.assertEqual(r.returncode, 1)
        self.assertIn("no runs under", r.stderr)
        self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    APPS, DATASETS = sys.argv[1], sys.argv[2]
    unittest.main(argv=sys.argv[:1] + sys.argv[3:], verbosity=2)  # skips with their reason (test.sh lists them)
