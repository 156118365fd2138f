"""kfd's launch files with the real ROS 1 parts (issue 24, "the node and nodelet run from the
launch files"), on the live harness (test/support/python/kfd_ros1_harness.py) (a roscore of its own on 127.0.0.1 and a free
port, every process killed at the end): `roslaunch kfd_ros kfd_bag.launch` with the node and
with the nodelet in the launch's own manager, `roslaunch kfd_ros kfd.launch manager:=...` into a
nodelet manager already running (the test plays the bag), each on the bag kfd_bench_fast_bag
writes, the filter's output recorded by `rosbag record` outside the launch: the kept scans must
be kfd-filter's, all of them (the launch keeps running after the bag: nothing is cut off), field
for field. And a bad key through the launch stops it, naming the key (the node, or the nodelet's
loader, is required and exits non-zero).
Usage: kfd_launch_test.py BUILD_APPS_DIR ROS_PACKAGE_DIR FAST_BAG_EXE NODELET_EXE [TEST...]
(ROS_PACKAGE_DIR: build/ros, which holds the package kfd_ros the build lays out.)"""
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import unittest
import xmlrpc.client

import kfd_ros1_harness as live  # test/support/python (PYTHONPATH: test/CMakeLists.txt)
from kfd_ros1_harness import _kill_group, scans_of

ROS_PKGS = FAST_BAG_EXE = NODELET_EXE = None
MANAGER = "kfd_manager"
# A config the fast bag shows (its defaults keep 5 % of the scans and remove no point): radius
# outlier removal after the keyframes, which removes a few points of the kept scans.
RADIUS = "[KFD]\npipeline = keyframe, radius\nradius_m = 0.05\nradius_min_neighbors = 3\n"
# Each keyframe held for its next scan, one at least every 3rd scan: of the fast bag's 160
# scans the last (159 = 53 x 3) is a keyframe, held when the filter is stopped (issue 38).
HELD = ("[KFD]\n[KFD.evidence_denoise]\nnext_scan = true\n"
        "[KFD.view_keyframe]\nmax_consecutive_drops = 2\n")
DATASETS = os.environ.get("KFD_DATASETS_DIR", "")


class KfdLaunch(live.RosCase):
    def setUp(self):
        super().setUp()
        if shutil.which("roslaunch") is None:
            self.skipTest("roslaunch not installed (Debian: ros-core)")
        if not os.path.isfile(os.path.join(ROS_PKGS, "kfd_ros", "lib", "libkfd_nodelet.so")):
            self.skipTest("kfd_nodelet not built in " + ROS_PKGS)
        if not NODELET_EXE or not os.access(NODELET_EXE, os.X_OK):
            self.skipTest("nodelet not installed (Debian: libnodeletlib-tools)")
        path = self.env.get("ROS_PACKAGE_PATH")
        self.env["ROS_PACKAGE_PATH"] = ROS_PKGS + (os.pathsep + path if path else "")

    def nodelet(self):
        """Skips a nodelet case in a sanitizer build: Debian's nodelet manager is not
        instrumented, so it cannot load an instrumented libkfd_nodelet.so (dlopen: undefined
        symbol __ubsan_vptr_type_cache). The GCC job runs these cases."""
        if os.environ.get("KFD_SANITIZED"):
            self.skipTest("sanitizer build: Debian's uninstrumented nodelet manager cannot load "
                          "the instrumented nodelet (the GCC job runs this case)")

    def fast_bag(self):
        if not FAST_BAG_EXE or not os.access(FAST_BAG_EXE, os.X_OK):
            self.skipTest("no bag writer (kfd_bench_fast_bag: Google Benchmark missing)")
        bag = os.path.join(self.tmp, "fast.bag")
        subprocess.run([FAST_BAG_EXE, bag, "none", "4", "40", "1081", "270", "0.01"], check=True,
                       stdout=subprocess.DEVNULL)
        return bag

    def roslaunch(self, launch, args):
        return self.start("roslaunch", ["roslaunch", "kfd_ros", launch] + list(args))

    def full_log(self, name):
        with open(os.path.join(self.tmp, name + ".log"), errors="replace") as f:
            return f.read()

    def pid_of(self, node):
        """The pid of a ROS node, asked through its XML-RPC API."""
        code, msg, uri = self.master.lookupNode("/kfd_test", node)
        self.assertEqual(code, 1, msg)
        with xmlrpc.client.ServerProxy(uri) as node_api:
            return node_api.getPid("/kfd_test")[2]

    def run_launch(self, launch, args, filter_node, scan_filtered="/scan_filtered",
                   external_manager=False, params=False, held=False, bag=None, stop="launch"):
        """Runs the launch file on the fast bag (or `bag`, with the launch's default odometry)
        with odom:=none, `rosbag record` outside it; checks the launch runs the filter as
        `filter_node` (/kfd: kfd_node; the manager: the nodelet) and that its kept scans are
        kfd-filter's, all of them. With `params`, the launch and kfd-filter take RADIUS (points
        removed) and removed_as:=inf; with `held`, HELD (a keyframe held at the end). `stop`:
        Ctrl-C on the launch ("launch"), `nodelet unload` ("unload") or SIGINT to the external
        manager ("manager"), each after the bag."""
        filter_args = [] if bag else ["--odom-topic", "none"]
        args = list(args) if bag else ["odom:=none"] + list(args)
        bag = bag or self.fast_bag()
        for wanted, name, text in ((params, "radius.ini", RADIUS), (held, "held.ini", HELD)):
            if not wanted:
                continue
            config = os.path.join(self.tmp, name)
            with open(config, "w") as f:
                f.write(text)
            args += ["config:=" + config]
            filter_args += ["-c", config]
        if params:
            args += ["removed_as:=inf"]
            filter_args += ["--removed-as", "inf"]
        out = os.path.join(self.tmp, "live.bag")
        recorder = self.start("record", ["rosbag", "record", "-O", out, "/scan", scan_filtered,
                                         "/kfd/stats"])
        self.wait_for(lambda: len(self.graph()[1].get(scan_filtered, [])) >= 1, 30,
                      "rosbag record to subscribe")
        manager = None
        if external_manager:
            manager = self.start("manager", [NODELET_EXE, "manager", "__name:=" + MANAGER])
            self.wait_for(lambda: self.master.lookupService(
                "/kfd_test", "/%s/load_nodelet" % MANAGER)[0] == 1, 30, "the nodelet manager")
        if launch == "kfd.launch":
            self.master.setParam("/kfd_test", "/use_sim_time", True)  # kfd_bag.launch sets it
        start = time.monotonic()
        launched = self.roslaunch(launch, args)

        def running(what):
            def cond():
                self.assertIsNone(launched.poll(), "the launch stopped: " + self.log_of(
                    "roslaunch"))
                return what()
            return cond

        if launch == "kfd.launch":
            # The test plays the bag once the filter and the recorder are connected.
            def connected():
                pubs, subs = self.graph()
                return (filter_node in subs.get("/scan", []) and
                        filter_node in pubs.get(scan_filtered, []) and
                        len(subs.get("/scan", [])) >= 2 and
                        len(subs.get("/kfd/stats", [])) >= 1)
            self.wait_for(running(connected), 60,
                          lambda: "kfd to start (graph %s; %s)" % (self.graph(),
                                                                   self.log_of("roslaunch")))
            time.sleep(1.0)  # the recorder connects to the filter's publishers
            play = self.start("play", ["rosbag", "play", "--clock", "-q", "-d",
                                       str(live.PLAY_DELAY_S), bag])
            play.wait(timeout=120)
            self.assertEqual(play.returncode, 0, self.log_of("play"))
        else:
            # kfd_bag.launch's player: it advertises, waits `delay` s (the filter and the
            # recorder connect), plays, exits; the launch goes on.
            self.wait_for(running(lambda: "/player" in self.graph()[0].get("/clock", [])), 60,
                          lambda: "the launch's player (%s)" % self.log_of("roslaunch"))
            self.wait_for(running(lambda: "/player" not in self.graph()[0].get("/clock", [])),
                          120, "the launch's player to finish")
        pubs = self.graph()[0]
        self.assertEqual(pubs.get(scan_filtered), [filter_node], pubs)
        self.assertEqual(pubs.get("/kfd/stats"), [filter_node], pubs)
        try:
            self.wait_idle(self.pid_of(filter_node))
        except OSError:  # /proc/PID/stat: the filter's process has gone
            self.fail("the filter exited: " + self.log_of("roslaunch"))
        self.assertIsNone(launched.poll(), "the launch stopped: " + self.log_of("roslaunch"))
        seconds = time.monotonic() - start
        self.stop_filter(stop, launched, manager)
        stats, kept, played = self.stop_recording(recorder, out, "/kfd/stats", scan_filtered)
        ref = self.kfd_filter(bag, filter_args)

        # Nothing lost: the recorder saw every scan of the bag, the filter every scan played
        # (none missing), and it published every scan kfd-filter keeps, the last ones too.
        self.assertEqual(int(stats["scans_missing"]), 0, stats)
        if held:
            log = self.full_log("manager" if external_manager else "roslaunch")
            self.assertIn("stopping (1 held keyframe published)", log)
        self.assertEqual(len(played), len(scans_of(bag, "/scan")))
        self.assertEqual(int(stats["scans_in"]), len(played), stats)
        self.assertEqual(int(stats["scans_kept"]), len(kept), stats)
        self.assertGreater(len(kept), 0)
        self.assertLess(len(kept), len(played))  # it drops scans
        self.assertEqual(len(kept), len(ref))
        self.assert_same_scans(kept, ref)
        # The launch's parameters reached the filter: RADIUS removes points, marked +Inf.
        removed = sum(1 for s in kept for x in s.ranges if x == float("inf"))
        if params:
            self.assertGreater(removed, 0)
        print("  %s %s: %d scans played, kept %d (kfd-filter %d), %d removed as +Inf; %.1f s"
              % (launch, " ".join(args).replace(self.tmp + "/", ""), len(played), len(kept),
                 len(ref), removed, seconds), flush=True)

    def stop_filter(self, how, launched, manager):
        """Stops the filter `how` (run_launch); the launch is gone afterwards."""
        if how == "launch":
            _kill_group(launched)  # SIGINT, as Ctrl-C: roslaunch stops its nodes
            self.assertNotIn("has died", self.full_log("roslaunch"))
            return
        if how == "unload":
            r = subprocess.run([NODELET_EXE, "unload", "/kfd", MANAGER], env=self.env,
                               capture_output=True, text=True, timeout=30)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            time.sleep(1.0)  # the manager goes on without kfd
            self.assertIsNone(manager.poll(), self.log_of("manager"))
        # SIGINT to the manager: with kfd loaded, kfd's stop (what it holds published); after
        # an unload, the manager's own handler again. Either way it exits 0 (and its log is
        # complete: rosconsole's stdout is buffered).
        os.kill(manager.pid, signal.SIGINT)
        manager.wait(timeout=10)
        self.assertEqual(manager.returncode, 0, self.log_of("manager"))
        # The loader's bond breaks: the launch (its loader is required) ends by itself.
        launched.wait(timeout=30)

    def run_failing(self, args, key):
        """kfd.launch with `args` stops by itself, naming the config key `key`; returns the
        exit code of the required process that died."""
        launched = self.roslaunch("kfd.launch", args)
        try:
            launched.wait(timeout=60)
        except subprocess.TimeoutExpired:
            self.fail("the launch did not stop: " + self.log_of("roslaunch"))
        log = self.full_log("roslaunch")
        self.assertIn("config key '%s'" % key, log)
        m = re.search(r"REQUIRED process \[kfd-\d+\] has died!\s*process has died "
                      r"\[pid \d+, exit code (-?\d+)", log)
        self.assertIsNotNone(m, log[-3000:])
        self.assertNotEqual(int(m.group(1)), 0, log[-3000:])
        return int(m.group(1))

    def test_bag_launch_node_matches_kfd_filter(self):
        self.run_launch("kfd_bag.launch", ["bag:=" + os.path.join(self.tmp, "fast.bag"),
                                           "delay:=3"], "/kfd", params=True)

    def test_bag_launch_nodelet_own_manager_matches_kfd_filter(self):
        self.nodelet()
        self.run_launch("kfd_bag.launch", ["bag:=" + os.path.join(self.tmp, "fast.bag"),
                                           "delay:=3", "manager:=" + MANAGER,
                                           "start_manager:=true"], "/" + MANAGER, held=True)

    def test_nodelet_unload_publishes_the_held_keyframe(self):
        self.nodelet()
        self.run_launch("kfd.launch", ["manager:=" + MANAGER], "/" + MANAGER,
                        external_manager=True, held=True, stop="unload")

    def test_manager_sigint_publishes_the_held_keyframe(self):
        self.nodelet()
        self.run_launch("kfd.launch", ["manager:=" + MANAGER], "/" + MANAGER,
                        external_manager=True, held=True, stop="manager")

    def test_readme_line_on_a_laser_only_bag_loses_nothing(self):
        """Issue 38: README's line on a real bag with no odometry (the default odom:=tf): no scan
        lost while the first ones wait for a transform that never comes, kfd-filter's kept
        scans, and the diagnostics say the odometry is missing."""
        bag = os.path.join(DATASETS, "ccny-urg", "demo.bag")
        if not DATASETS or not os.path.isfile(bag):
            self.skipTest("dataset missing: %s (KFD_DATASETS_DIR)" % bag)
        self.run_launch("kfd_bag.launch", ["bag:=" + bag, "rate:=2"], "/kfd", bag=bag)
        self.assertIn("no odometry for the scan", self.full_log("roslaunch"))

    def test_launch_nodelet_into_running_manager_matches_kfd_filter(self):
        self.nodelet()
        self.run_launch("kfd.launch", ["manager:=" + MANAGER, "scan_filtered:=/scan_kfd"],
                        "/" + MANAGER, scan_filtered="/scan_kfd", external_manager=True,
                        params=True)

    def test_bad_key_stops_node_launch(self):
        self.assertEqual(self.run_failing(["removed_as:=bogus"], "removed_as"), 2)

    def test_bad_config_key_stops_nodelet_launch(self):
        self.nodelet()
        config = os.path.join(self.tmp, "bad.ini")
        with open(config, "w") as f:
            f.write("[KFD]\nwindw = 3\n")
        self.run_failing(["config:=" + config, "manager:=" + MANAGER, "start_manager:=true"],
                         "windw")


if __name__ == "__main__":
    live.APPS = os.path.abspath(sys.argv[1])
    ROS_PKGS = os.path.abspath(sys.argv[2])
    FAST_BAG_EXE = os.path.abspath(sys.argv[3]) if len(sys.argv) > 3 and sys.argv[3] else ""
    NODELET_EXE = os.path.abspath(sys.argv[4]) if len(sys.argv) > 4 and sys.argv[4] else ""
    unittest.main(argv=sys.argv[:1] + sys.argv[5:], verbosity=2)  # skips with their reason
