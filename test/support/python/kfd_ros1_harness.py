"""The live ROS 1 harness of kfd's tests and benchmarks (shared test support, never a test
itself): a roscore of its own on 127.0.0.1 and a free port, kfd_node with use_sim_time,
`rosbag record` of its scan_filtered and ~stats, `rosbag play --clock` of a bag, kfd-filter on
the same bag for reference. Everything it starts runs in its own process group and is killed
at the end of each test, on failure, on SIGTERM/SIGINT and at exit.
Users: test/scripts/kfd_node_live_test.py, test/scripts/kfd_launch_test.py,
scripts/bench/ros_bench.py, scripts/experiments/ros_figure.py. They import it by name, with
test/support/python on PYTHONPATH (ctest sets it; the scripts' usage lines say so). Set APPS
(and DATASETS, FAST_BAG_EXE where used) before a case runs."""
import atexit
import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest
import xmlrpc.client

APPS = DATASETS = FAST_BAG_EXE = None
_GROUPS = set()  # process groups started and not yet reaped
_TAGS = set()  # the tests' temp dirs: every ROS process of a test names its own
PLAY_DELAY_S = 2  # rosbag play -d: s between advertising /scan and the first message


def _kill_group(proc, first=signal.SIGINT, wait=10.0):
    """Stops proc's process group: `first`, then SIGTERM, then SIGKILL."""
    if proc.poll() is None:
        for sig, t in ((first, wait), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
            try:
                os.killpg(proc.pid, sig)
            except ProcessLookupError:
                break
            try:
                proc.wait(timeout=t)
                break
            except subprocess.TimeoutExpired:
                continue
    # The group's other processes (roscore's rosmaster and rosout, rosbag's recorder, which
    # renames its bag when it closes) finish after the leader: wait for them, then kill what is
    # left.
    end = time.monotonic() + wait
    while time.monotonic() < end:
        try:
            os.killpg(proc.pid, 0)
        except (ProcessLookupError, PermissionError):
            break
        time.sleep(0.1)
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    _GROUPS.discard(proc.pid)


def _kill_tagged(tag):
    """Kills every process whose command line names `tag` (a test's own temp dir): roscore
    starts rosmaster and rosout in sessions of their own (their __log:= is under ROS_LOG_DIR)."""
    for pid in os.listdir("/proc"):
        if not pid.isdigit() or int(pid) == os.getpid():
            continue
        try:
            with open("/proc/%s/cmdline" % pid, "rb") as f:
                cmd = f.read()
        except OSError:
            continue
        if tag.encode() in cmd:
            try:
                os.kill(int(pid), signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass


def _kill_all():
    for tag in list(_TAGS):
        _kill_tagged(tag)
    for pgid in list(_GROUPS):
        try:
            os.killpg(pgid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        _GROUPS.discard(pgid)


def _on_signal(signum, _frame):
    _kill_all()
    sys.exit(128 + signum)


atexit.register(_kill_all)
signal.signal(signal.SIGTERM, _on_signal)
signal.signal(signal.SIGINT, _on_signal)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class _TimeoutTransport(xmlrpc.client.Transport):
    """An XML-RPC transport whose calls give up after `timeout` s: a port that accepts and
    never answers (a process other than rosmaster on it) would block a plain ServerProxy."""

    def __init__(self, timeout):
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host):
        conn = super().make_connection(host)
        conn.timeout = self._timeout
        return conn


def scans_of(bag_path, topic):
    import rosbag
    with rosbag.Bag(bag_path) as b:
        return [m for _, m, _ in b.read_messages(topics=[topic])]


def cpu_seconds(pid):
    """User + system CPU time of a process so far (s), from /proc/PID/stat."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def same_floats(a, b):
    """Equal element by element, NaN equal to NaN (and only to NaN)."""
    if len(a) != len(b):
        return False
    return all((math.isnan(x) and math.isnan(y)) or x == y for x, y in zip(a, b))


def diff(a, b):
    """How two scans' ranges differ (beam: node, kfd-filter), for a failure message."""
    d = [(i, x, y) for i, (x, y) in enumerate(zip(a.ranges, b.ranges))
         if not ((math.isnan(x) and math.isnan(y)) or x == y)]
    return "%d ranges differ (beam, node, kfd-filter): %s" % (len(d), d[:6])


class RosCase(unittest.TestCase):
    """The harness (kfd_launch_test.py uses it too): per test a temp dir, a roscore of its own
    (self.uri, self.master, self.env), processes started in groups of their own (start) and
    killed at the end of the test."""

    def setUp(self):
        try:
            import rosbag  # noqa: F401
        except ImportError:
            self.skipTest("python3-rosbag not installed")
        for tool in ("roscore", "rosbag"):
            if shutil.which(tool) is None:
                self.skipTest(tool + " not installed (Debian: ros-core, python3-rosbag)")
        self.node_exe = os.path.join(APPS, "kfd_node")
        if not os.access(self.node_exe, os.X_OK):
            self.skipTest("kfd_node not built: " + self.node_exe)
        self.tmp = tempfile.mkdtemp(prefix="kfd_node_live_")
        self.addCleanup(shutil.rmtree, self.tmp, ignore_errors=True)
        _TAGS.add(self.tmp)
        self.addCleanup(_TAGS.discard, self.tmp)
        self.addCleanup(_kill_tagged, self.tmp)  # runs after the groups are stopped
        self.start_roscore()

    def start_roscore(self, attempts=3, seconds=45):
        """A roscore of its own on a free port (self.uri, self.master, self.env). The port is
        free when chosen, but another process may bind it before rosmaster does, and CI once
        saw a roscore that never answered (its log was not kept): when roscore exits or does
        not answer, it tries again on another port, and a last failure shows roscore's log."""
        for attempt in range(1, attempts + 1):
            port = free_port()
            self.uri = "http://127.0.0.1:%d" % port
            self.env = dict(os.environ)
            for k in ("ROS_HOSTNAME", "ROS_NAMESPACE"):
                self.env.pop(k, None)
            self.env.update(ROS_MASTER_URI=self.uri, ROS_IP="127.0.0.1",
                            ROS_HOME=os.path.join(self.tmp, "ros_home"),
                            ROS_LOG_DIR=os.path.join(self.tmp, "ros_log"))
            self.master = xmlrpc.client.ServerProxy(self.uri, transport=_TimeoutTransport(10))
            self.addCleanup(self.master("close"))
            name = "roscore" if attempt == 1 else "roscore%d" % attempt
            core = self.start(name, ["roscore", "-p", str(port)])
            if self.poll_until(lambda: self.master.getSystemState("/kfd_test")[0] == 1, seconds,
                         lambda: core.poll() is None):
                return
            _kill_group(core)
        self.fail("roscore did not answer on %s in %d attempts; its log:\n%s"
                  % (self.uri, attempts, self.log_of(name)))


    def stop_recording(self, recorder, out, stats_topic, filtered_topic):
        """Stops `rosbag record` (a second after the filter, whose last ~stats it records) and
        returns (the last ~stats as a dict, the filtered scans, the /scan messages) of `out`."""
        time.sleep(1.0)
        _kill_group(recorder)
        self.assertTrue(os.path.isfile(out), "no recorded bag: " + self.log_of("record"))
        import rosbag
        stats = None
        with rosbag.Bag(out) as b:
            for _, m, _ in b.read_messages(topics=[stats_topic]):
                stats = {kv.key: kv.value for kv in m.values}
        self.assertIsNotNone(stats, "no ~stats recorded")
        return stats, scans_of(out, filtered_topic), scans_of(out, "/scan")
    def start(self, name, argv):
        log = open(os.path.join(self.tmp, name + ".log"), "w")
        self.addCleanup(log.close)
        p = subprocess.Popen(argv, env=self.env, cwd=self.tmp, stdout=log, stderr=subprocess.STDOUT,
                             stdin=subprocess.DEVNULL, start_new_session=True)
        _GROUPS.add(p.pid)
        self.addCleanup(_kill_group, p)
        return p

    def log_of(self, name):
        try:
            with open(os.path.join(self.tmp, name + ".log")) as f:
                return f.read()[-3000:]
        except OSError:
            return ""

    @staticmethod
    def poll_until(cond, seconds, alive=lambda: True):
        """True once cond() holds, checked every 0.1 s (a connection or XML-RPC error counts
        as not yet); False after `seconds`, or as soon as alive() is false."""
        end = time.monotonic() + seconds
        while time.monotonic() < end and alive():
            try:
                if cond():
                    return True
            except (ConnectionError, OSError, xmlrpc.client.Fault):
                pass
            time.sleep(0.1)
        return False

    def wait_for(self, cond, seconds, what):
        if not self.poll_until(cond, seconds):
            self.fail("timed out waiting for " + (what() if callable(what) else what))

    def graph(self):
        _, _, (pubs, subs, _) = self.master.getSystemState("/kfd_test")
        return dict(pubs), dict(subs)

    def wait_idle(self, pid, seconds=120):
        """Waits until process `pid` is idle, at most 1 % of a core over 2 s (a scan waiting for
        /tf polls every 0.5 ms; idle, the node only wakes for its 1 Hz timer), at most
        `seconds`: the node works off its queue (under load it lags the player)."""
        settle_until = time.monotonic() + seconds
        samples = [cpu_seconds(pid)]
        while time.monotonic() < settle_until:
            time.sleep(1.0)
            samples.append(cpu_seconds(pid))
            if len(samples) >= 3 and samples[-1] - samples[-3] <= 0.02:
                break

    def kfd_filter(self, bag, args=()):
        """kfd-filter -i bag: its kept scans."""
        ref = os.path.join(self.tmp, "ref.bag")
        r = subprocess.run([os.path.join(APPS, "kfd-filter"), "-q", "-i", bag, "-o", ref]
                           + list(args), capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        return scans_of(ref, "/scan")

    def assert_same_scans(self, kept, ref):
        """The node's kept scans are kfd-filter's first len(kept), field for field; returns the
        number of NaN ranges in them."""
        nan_points = 0
        for i, (a, b) in enumerate(zip(kept, ref)):
            where = "kept scan %d (node stamp %s, kfd-filter stamp %s)" % (
                i, a.header.stamp.to_sec(), b.header.stamp.to_sec())
            self.assertEqual(a.header.stamp, b.header.stamp, where)
            self.assertEqual(a.header.frame_id, b.header.frame_id, where)
            self.assertEqual((a.angle_min, a.angle_max, a.angle_increment, a.time_increment,
                              a.scan_time, a.range_min, a.range_max),
                             (b.angle_min, b.angle_max, b.angle_increment, b.time_increment,
                              b.scan_time, b.range_min, b.range_max), where)
            self.assertTrue(same_floats(a.ranges, b.ranges), "%s: %s" % (where, diff(a, b)))
            self.assertTrue(same_floats(a.intensities, b.intensities), where)
            nan_points += sum(1 for x in a.ranges if math.isnan(x))
        return nan_points


class LiveHarness(RosCase):
    """RosCase with kfd_node run live on a bag and compared with kfd-filter."""

    def stop_node(self, node, how):
        """Stops kfd_node `how`: "int" (SIGINT, Ctrl-C), "term" (SIGTERM) or "kill" (`rosnode
        kill`, the master's shutdown call); checks it exits 0 within 10 s."""
        if how == "kill":
            subprocess.run(["rosnode", "kill", "/kfd_node"], env=self.env, check=True,
                           capture_output=True, timeout=30)
        else:
            os.kill(node.pid, signal.SIGINT if how == "int" else signal.SIGTERM)
        try:
            node.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.fail("kfd_node did not stop within 10 s of %s: %s" % (how, self.log_of("kfd_node")))
        self.assertEqual(node.returncode, 0, self.log_of("kfd_node"))

    def run_live(self, bag, node_args=(), play_args=(), filter_args=(), stop="int"):
        """Plays `bag` into kfd_node, then stops it (stop_node); returns (recorded kept scans,
        final stats dict, /scan messages the recorder saw, kfd-filter's kept scans)."""
        out = os.path.join(self.tmp, "live.bag")
        recorder = self.start("record", ["rosbag", "record", "-O", out, "/scan", "/scan_filtered",
                                         "/kfd_node/stats"])
        # The recorder on wall time (use_sim_time is set after it starts): it writes whatever
        # comes, without waiting for /clock; the node on the bag's clock.
        self.wait_for(lambda: len(self.graph()[1].get("/scan_filtered", [])) >= 1, 30,
                      "rosbag record to subscribe")
        self.master.setParam("/kfd_test", "/use_sim_time", True)
        node = self.start("kfd_node", [self.node_exe, "__name:=kfd_node"] + list(node_args))

        def connected():
            pubs, subs = self.graph()
            return ("/kfd_node" in subs.get("/scan", []) and
                    "/kfd_node" in pubs.get("/scan_filtered", []) and
                    "/kfd_node" in pubs.get("/kfd_node/stats", []) and
                    len(subs.get("/scan", [])) >= 2 and  # the node and the recorder
                    len(subs.get("/scan_filtered", [])) >= 1 and
                    len(subs.get("/kfd_node/stats", [])) >= 1)  # the recorder
        self.wait_for(lambda: node.poll() is None and connected(), 30,
                      lambda: "kfd_node and the recorder to register (kfd_node's log: %s; "
                      "graph %s)" % (self.log_of("kfd_node"), self.graph()))
        time.sleep(1.0)  # the recorder connects to the node's publishers
        cpu0, wall0 = cpu_seconds(node.pid), time.monotonic()
        # -d 2: the player waits 2 s after advertising /scan before its first message, time for
        # the node and the recorder to connect to it (0.5 s once lost a first scan under load).
        play = self.start("play", ["rosbag", "play", "--clock", "-q", "-d", str(PLAY_DELAY_S),
                                   bag] + list(play_args))
        try:
            play.wait(timeout=600)
        except subprocess.TimeoutExpired:
            self.fail("rosbag play did not finish")
        self.assertEqual(play.returncode, 0, self.log_of("play"))
        self.node_cpu = (cpu_seconds(node.pid) - cpu0,  # the bench's: from the first message
                         time.monotonic() - wall0 - PLAY_DELAY_S)
        self.wait_idle(node.pid)
        self.assertIsNone(node.poll(), "kfd_node died: " + self.log_of("kfd_node"))
        self.stop_node(node, stop)  # it publishes what it holds and ~stats once more
        stats, kept, played = self.stop_recording(recorder, out, "/kfd_node/stats",
                                                  "/scan_filtered")
        return kept, stats, played, self.kfd_filter(bag, filter_args)

    def prefix(self, bag, seconds, tail=2.0):
        """The first `seconds` of `bag`'s scans with `tail` seconds more of everything else (the
        odometry after the last scan, as on a robot that keeps running), messages copied raw."""
        import rosbag
        out = os.path.join(self.tmp, "prefix.bag")
        with rosbag.Bag(bag) as src, rosbag.Bag(out, "w") as dst:
            t0 = src.get_start_time()
            for topic, raw, t in src.read_messages(raw=True, return_connection_header=False):
                dt = t.to_sec() - t0
                if dt > seconds + tail:
                    break
                if topic == "/scan" and dt > seconds:
                    continue
                dst.write(topic, raw, t, raw=True)
        return out

    def check(self, bag, seconds=None, rate=1.0, odom="tf", node_args=(), filter_args=(),
              stop="int"):
        """The node against kfd-filter on the first `seconds` of `bag`'s scans, played at
        `rate`, the node stopped `stop` (stop_node)."""
        if seconds:
            bag = self.prefix(bag, seconds)
        node_args = ["_odom:=" + odom] + list(node_args)
        kept, stats, played, ref = self.run_live(
            bag, node_args, ["-r", str(rate)], ["--odom-topic", odom] + list(filter_args), stop)

        # Nothing lost: the recorder saw every scan of the bag, the node every scan played.
        self.assertEqual(len(played), len(scans_of(bag, "/scan")))
        self.assertEqual(int(stats["scans_in"]), len(played), stats)
        self.assertEqual(int(stats["scans_kept"]), len(kept), stats)
        self.assertGreater(len(kept), 0)
        self.assertLess(len(kept), len(played))  # it drops scans
        self.assertLessEqual(len(kept), len(ref))

        # The node's kept scans are kfd-filter's first N, field for field.
        nan_points = self.assert_same_scans(kept, ref)
        self.ref_count = len(ref)
        print("  %s: %d scans played, node kept %d (kfd-filter %d), "
              "%d NaN ranges; p50 %s us, p99 %s us" % (
                  os.path.basename(bag), len(played), len(kept), len(ref), nan_points,
                  stats.get("latency_p50_us"), stats.get("latency_p99_us")), flush=True)
        return kept, stats

    # The real bags run on the node's defaults: its wait for odometry (~tf_wait, 1 s of ROS time)
    # covers the Freiburg logs' odometry, which comes up to 210 ms of bag time after a scan
    # (intel: 640 ms; 55 of its first 305 scans over 200 ms).
    def dataset(self, rel):
        path = os.path.join(DATASETS or "", rel)
        if not DATASETS or not os.path.isfile(path):
            self.skipTest("dataset missing: %s (KFD_DATASETS_DIR)" % path)
        return path
