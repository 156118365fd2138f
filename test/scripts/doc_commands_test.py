"""The README's and docs/USAGE.md's commands run as shown, and USAGE matches every tool's --help.

Every command in a ```sh block and every inline `kfd-...` command of README.md and docs/USAGE.md
runs, in document order, in a scratch folder that looks like the source tree (share/, rawlogs/,
scripts/, build/apps/ linked in), on the bundled simulated log: placeholders (IN.rawlog, LOG,
CONFIG, GT.relations, N, ...) become the bundled log and its files, an optional part [...] is run
both left out and put in, and the first choice of a|b is taken. Each must exit 0 and write the
files its -o/--out/--stats name. The few commands not run here say why (NOT_RUN).
USAGE matches --help: every option a tool's --help lists is in USAGE.md, and every --option
USAGE.md names is one some tool has.
Usage: doc_commands_test.py SOURCE_DIR APPS_DIR"""
import math
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import unittest

SRC = APPS = None
BUNDLED = "rawlogs/office-mit-0.752.rawlog"

# Commands shown but not run by this test, with the reason (matched on the command's start).
NOT_RUN = {
    "bash scripts/demo.sh": "the demo_script test runs it on a clean copy of the tree",
    "bash scripts/test.sh": "it is the test suite",
    "bash scripts/bench/bench.sh": "benchmarks (minutes of callgrind; docs/RESULTS.md)",
    "cmake -S examples/filter_log": "the library example: package_consumer builds it against an "
    "installed tree and runs it",
    "cmake --build build-example": "the library example (package_consumer runs it)",
    "parallel ": "runs kfd-compare's emitted jobs (kfd_compare_test runs them with GNU parallel)",
    "xargs ": "runs kfd-compare's emitted jobs (as parallel does)",
    "sh -c ": "a Slurm array task's line (runs one emitted job)",
    "kfd-compare --datasets": "an option of kfd-compare run, quoted in a sentence",
    "kfd-compare configs": "needs a finished comparison with two configs (kfd_compare_test runs "
    "it on hand-made runs)",
    "kfd-compare curve": "needs a finished comparison with several configs (kfd_compare_test "
    "runs it on hand-made runs)",
    "export ROS_PACKAGE_PATH": "ROS 1 node: needs a ROS master (the ros1 tests run the node)",
    "ROS_PACKAGE_PATH=build/ros roslaunch ": "ROS 1 launch: needs a ROS master (kfd_launch_test "
    "runs both launch files)",
    "roslaunch ": "ROS 1 launch: needs a ROS master (kfd_launch_test runs both launch files)",
    "build/apps/kfd_node": "ROS 1 node: needs a ROS master (the ros1 tests run the node)",
    "/usr/lib/nodelet/nodelet": "ROS 1 nodelet: needs a ROS master and a nodelet manager",
}

TOOLS = ["kfd-filter", "kfd-icp-slam", "kfd-eval", "kfd-simulate", "kfd-inject",
         "kfd-denoise-eval", "kfd-render", "kfd-chart"]


def shown_commands(path):
    """(command, where) in document order: ```sh blocks (continuations joined, comments cut)
    and inline code spans that start with a kfd tool and have arguments."""
    text = open(path, encoding="utf-8").read()
    found = []
    for m in re.finditer(r"```sh\n(.*?)```", text, re.S):
        line_no = text.count("\n", 0, m.start()) + 2
        buf = ""
        for i, line in enumerate(m.group(1).splitlines()):
            line = re.sub(r"\s+#\s.*$", "", line).rstrip()
            if line.endswith("\\"):
                buf += line[:-1] + " "
                continue
            buf += line
            if buf.strip():
                found.append((re.sub(r"\s+", " ", buf.strip()), f"{path}:{line_no + i}"))
            buf = ""
    for m in re.finditer(r"(?<!`)`((?:build/apps/|scripts/|bin/)?kfd-[a-z-]+ [^`]+)`(?!`)", text):
        if text.rfind("```", 0, m.start()) != -1 and text[:m.start()].count("```") % 2:
            continue  # inside a fenced block
        line_no = text.count("\n", 0, m.start()) + 1
        found.append((re.sub(r"\s+", " ", m.group(1).strip()), f"{path}:{line_no}"))
    return found


def variants(cmd):
    """The command with its optional parts [...] left out, and with them put in."""
    out = [re.sub(r"\s*\[[^\[\]]*\]", "", cmd)]
    full = re.sub(r"\[([^\[\]]*)\]", r"\1", cmd)
    if full != out[0]:
        out.append(full)
    return out


def write_relations(tum, relations, step=20):
    """Kümmerle-style relations (t1 t2 dx dy 0 0 0 dyaw, in the first pose's frame) between
    every step-th pose of a TUM trajectory and the next such pose."""
    poses = []
    for line in open(tum):
        f = line.split()
        if len(f) != 8 or line.startswith("#"):
            continue
        t, x, y, qz, qw = float(f[0]), float(f[1]), float(f[2]), float(f[6]), float(f[7])
        poses.append((t, x, y, 2.0 * math.atan2(qz, qw)))
    with open(relations, "w") as out:
        for a, b in zip(poses[::step], poses[step::step]):
            dx, dy = b[1] - a[1], b[2] - a[2]
            c, s = math.cos(a[3]), math.sin(a[3])
            dyaw = math.atan2(math.sin(b[3] - a[3]), math.cos(b[3] - a[3]))
            out.write(f"{a[0]:.6f} {b[0]:.6f} {c * dx + s * dy:.6f} {-s * dx + c * dy:.6f} "
                      f"0 0 0 {dyaw:.6f}\n")


class Scratch:
    """A folder that looks like the source tree, with the bundled log's inputs made."""

    def __init__(self, name):
        self.dir = tempfile.mkdtemp(prefix=f"kfd_doc_{name}_", dir=os.environ.get("TMPDIR"))
        for sub in ("share", "rawlogs", "scripts", "python"):
            os.symlink(os.path.join(SRC, sub), os.path.join(self.dir, sub))
        os.makedirs(os.path.join(self.dir, "build"))
        os.symlink(APPS, os.path.join(self.dir, "build", "apps"))
        os.makedirs(os.path.join(self.dir, "in"))
        write_relations(os.path.join(SRC, "rawlogs/office-mit-0.752.gt.tum"),
                        os.path.join(self.dir, "in/gt.relations"))
        self.last_compare_run = None

    def run(self, args, timeout=600):
        env = dict(os.environ)
        env["PATH"] = APPS + os.pathsep + os.path.join(SRC, "scripts") + os.pathsep + env["PATH"]
        env["PYTHONPATH"] = os.path.join(SRC, "python")
        return subprocess.run(args, cwd=self.dir, env=env, capture_output=True, text=True,
                              timeout=timeout)

    def run_node(self, args):
        """kfd_ros2 as shown, live for 3 s on 127.0.0.1 only (ROS_LOCALHOST_ONLY=1, a domain of
        its own), then Ctrl-C: the exit status of a clean stop, 0, and its log."""
        env = dict(os.environ, ROS_LOCALHOST_ONLY="1", ROS_DOMAIN_ID=str(150 + os.getpid() % 80))
        if "ASAN_OPTIONS" in env:  # the sanitizer job: Fast DDS's own mismatch (test/CMakeLists.txt)
            env["ASAN_OPTIONS"] += ":new_delete_type_mismatch=0"
        p = subprocess.Popen(args, cwd=self.dir, env=env, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        try:
            out, err = p.communicate(timeout=3)  # it exited by itself: a refused start
        except subprocess.TimeoutExpired:
            p.send_signal(signal.SIGINT)
            out, err = p.communicate(timeout=20)
        return subprocess.CompletedProcess(args, p.returncode, out, err)

    def log_as(self, ext):
        """A bag (kfd_bench_fast_bag's: /scan with odometry and other high-rate topics, 3 s;
        the bundled log has no bag form), that bag as a rosbag2 .db3, or the bundled log as a
        CARMEN log (kfd-filter's, every scan kept), written once."""
        path = os.path.join(self.dir, "in", "office" + ext)
        if not os.path.exists(path) and ext == ".bag":
            exe = os.environ.get("KFD_FAST_BAG_EXE", "")
            if not os.path.exists(exe):
                raise unittest.SkipTest("no bag writer (kfd_bench_fast_bag: Google Benchmark "
                                        "not built)")
            r = self.run([exe, path, "bz2", "3"])
            if r.returncode != 0:
                raise AssertionError(f"cannot write a test bag: {r.stderr}")
        elif not os.path.exists(path):
            keep = os.path.join(self.dir, "in", "keep-all.ini")
            with open(keep, "w") as f:
                f.write("[KFD]\npipeline = distance\n")
            # A ROS 2 bag (.db3) is made of the test bag; a CARMEN log of the bundled log.
            source = self.log_as(".bag") if ext == ".db3" else BUNDLED
            r = self.run([os.path.join(APPS, "kfd-filter"), "-i", source, "-o", path,
                          "-c", keep, "-q"])
            if r.returncode != 0:
                raise AssertionError(f"cannot write the bundled log as {ext}: {r.stderr}")
        return path


PLACEHOLDERS = {
    "IN.rawlog": BUNDLED, "LOG": BUNDLED, "LOG.rawlog": BUNDLED, "REAL.rawlog": BUNDLED,
    "my.rawlog": BUNDLED, "CONFIG": "share/kfd/default.ini", "GT.relations": "in/gt.relations",
    "GT.tum": "rawlogs/office-mit-0.752.gt.tum", "N": "300", "DIR": "in",
}


def resolve(scratch, cmd):
    """argv for a shown command, or raise AssertionError naming an unknown placeholder."""
    tokens = shlex.split(cmd)
    if tokens[0].startswith("build/apps/") or tokens[0].startswith("bin/"):
        if not os.path.exists(os.path.join(APPS, os.path.basename(tokens[0]))):
            raise unittest.SkipTest(f"{tokens[0]} is not built here")
        tokens[0] = os.path.join(APPS, os.path.basename(tokens[0]))
    elif tokens[0] in TOOLS:
        tokens[0] = os.path.join(APPS, tokens[0])
    elif tokens[0] in ("kfd-compare", "scripts/kfd-compare"):
        tokens[0] = os.path.join(SRC, "scripts", "kfd-compare")
    argv = []
    for i, tok in enumerate(tokens):
        if "|" in tok and not tok.startswith("-"):
            choices = tok.split("|")
            tok = next((c for c in choices if c not in PLACEHOLDERS and c != "T"), choices[0])
        prev = tokens[i - 1] if i else ""
        if tok in ("IN.bag", "X.bag"):
            tok = scratch.log_as(".bag")
        elif tok == "ROSBAG2_DIR":
            tok = scratch.log_as(".db3")
        elif tok == "IN.clf":
            tok = scratch.log_as(".clf")
        elif tok == "T":
            tok = "/scan"
        elif tok == "NAME" and prev == "--model":
            tok = "spike_uniform"
        elif tok == "CSV":
            tok = os.path.join(scratch.dir, "in", "bars.csv")
            with open(tok, "w") as f:
                f.write("group,series,value,error\naces,none,0.05,0.01\naces,kfd,0.04,0.01\n")
        elif tok == "MODE":
            tok = "none"
        elif tok == "COMMAND":
            tok = "run"
        elif tok in ("A", "B") and ("--modes" in tokens[:i]):
            tok = {"A": "none", "B": "kfd"}[tok]
        elif tok in PLACEHOLDERS:
            tok = PLACEHOLDERS[tok]
        elif tok == "...":
            if scratch.last_compare_run is None:
                raise AssertionError("'...' before any kfd-compare run command")
            argv.extend(scratch.last_compare_run)
            continue
        argv.append(tok)
    return argv


def outputs(argv):
    """The files and folders a command names as its outputs."""
    named = []
    for i, tok in enumerate(argv[:-1]):
        if tok in ("-o", "--out", "--stats", "--emit-jobs"):
            named.append(argv[i + 1])
    return named


class DocCommands(unittest.TestCase):
    def check_doc(self, doc):
        scratch = Scratch(os.path.basename(doc).split(".")[0])
        try:
            ran = 0
            for cmd, where in shown_commands(os.path.join(SRC, doc)):
                reason = next((r for k, r in NOT_RUN.items() if cmd.startswith(k)), None)
                if reason:
                    print(f"  not run  {where}: {cmd}  ({reason})")
                    continue
                for variant in variants(cmd):
                    with self.subTest(command=variant, where=where):
                        argv = resolve(scratch, variant)
                        if argv[0].endswith("kfd-compare") and "run" in argv[1:2]:
                            argv = self.compare_run(scratch, argv)
                        live = os.path.basename(argv[0]) == "kfd_ros2" and "--help" not in argv
                        r = scratch.run_node(argv) if live else scratch.run(argv)
                        if live:
                            self.assertIn("stopped:", r.stderr, f"{where}: {variant}")
                        self.assertEqual(r.returncode, 0,
                                         f"{where}: {variant}\n-> {shlex.join(argv)}\n"
                                         f"exit {r.returncode}\n{r.stdout[-1500:]}"
                                         f"{r.stderr[-1500:]}")
                        for out in outputs(argv):
                            self.assertTrue(os.path.exists(os.path.join(scratch.dir, out)),
                                            f"{where}: {variant}: {out} not written")
                        ran += 1
                        print(f"  ran      {where}: {variant}")
            self.assertGreater(ran, 5, f"{doc}: too few commands found")
        finally:
            shutil.rmtree(scratch.dir, ignore_errors=True)

    def compare_run(self, scratch, argv):
        """kfd-compare run as shown (its real-log names and 20 repeats are hours of CPU):
        its jobs are emitted (the options and logs are checked) and one small real run on the
        bundled log fills the output folder for the collect and diagnose commands after it."""
        args = argv[2:]
        if "--help" in args or "-h" in args:
            return argv
        scratch.last_compare_run = [a for a in args if a != "..."]
        for opt, tool in (("--exe", "kfd-icp-slam"), ("--sim-exe", "kfd-simulate")):
            if opt not in args:  # this build's apps (the tree may have no build/apps)
                args += [opt, os.path.join(APPS, tool)]
        datasets = os.environ.get("KFD_DATASETS_DIR", "")
        logs_at = args.index("--logs") if "--logs" in args else -1
        if logs_at >= 0:
            i = logs_at + 1
            while i < len(args) and not args[i].startswith("-"):
                if not args[i].endswith(".rawlog") and not os.path.isdir(
                        os.path.join(datasets, args[i])):
                    args[i] = BUNDLED  # a dataset name without the datasets: the bundled log
                i += 1
        if "--datasets" not in args and datasets:
            args += ["--datasets", datasets]
        emitted = argv[:2] + args + (["--emit-jobs", "jobs.txt"]
                                     if "--emit-jobs" not in args else [])
        out = args[args.index("--out") + 1] if "--out" in args else None
        if out and not os.path.exists(os.path.join(scratch.dir, out, "runs")):
            r = scratch.run(argv[:2] + ["--logs", BUNDLED, "--modes", "none", "kfd",
                                        "--repeats", "2", "--jobs", "2", "-q", "--out", out,
                                        "--exe", os.path.join(APPS, "kfd-icp-slam")])
            self.assertEqual(r.returncode, 0, f"small kfd-compare run: {r.stderr[-1500:]}")
        return emitted

    def test_readme_commands_run(self):
        self.check_doc("README.md")

    def test_usage_commands_run(self):
        self.check_doc("docs/USAGE.md")


def help_options(argv):
    """The options a --help lists, each as the tuple of its names ("-i", "--input")."""
    r = subprocess.run(argv + ["--help"], capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        raise AssertionError(f"{shlex.join(argv)} --help exited {r.returncode}: {r.stderr}")
    opts = set()
    for line in r.stdout.splitlines():
        m = re.match(r"^\s{1,6}(-{1,2}[a-zA-Z][\w-]*(?:,\s?-{1,2}[a-zA-Z][\w-]*)*)", line)
        if m:
            opts.add(tuple(n.strip() for n in m.group(1).split(",")))
    return opts


def mentioned(text, name):
    return re.search(r"(?<![\w-])" + re.escape(name) + r"(?![\w-])", text) is not None


class UsageMatchesHelp(unittest.TestCase):
    def setUp(self):
        self.usage = open(os.path.join(SRC, "docs/USAGE.md"), encoding="utf-8").read()
        self.helps = {t: help_options([os.path.join(APPS, t)]) for t in TOOLS}
        if os.path.exists(os.path.join(APPS, "kfd_ros2")):  # built with Fast DDS
            self.helps["kfd_ros2"] = help_options([os.path.join(APPS, "kfd_ros2")])
        compare = [os.path.join(SRC, "scripts", "kfd-compare")]
        for sub in ("run", "job", "collect", "diagnose", "curve"):
            r = subprocess.run(compare + [sub, "--help"], capture_output=True, text=True)
            if r.returncode == 0:
                self.helps["kfd-compare " + sub] = help_options(compare + [sub])

    def test_every_option_of_every_tool_is_in_usage(self):
        for tool, opts in self.helps.items():
            for names in sorted(opts):
                if "--help" in names:
                    continue
                with self.subTest(tool=tool, option=names):
                    self.assertTrue(any(mentioned(self.usage, n) for n in names),
                                    f"{tool} {'/'.join(names)} is not in docs/USAGE.md")

    def test_every_option_usage_names_exists(self):
        known = {n for opts in self.helps.values() for names in opts for n in names}
        named = set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", self.usage))
        # Options of other programs that USAGE quotes.
        others = {"--tool", "--output-on-failure", "--target", "--build", "--install", "--clock"}
        for opt in sorted(named - known - others):
            with self.subTest(option=opt):
                self.fail(f"docs/USAGE.md names {opt}, which no kfd tool's --help lists")


if __name__ == "__main__":
    SRC, APPS = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    unittest.main(argv=sys.argv[:1], verbosity=2)
