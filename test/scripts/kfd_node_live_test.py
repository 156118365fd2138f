"""kfd_node live, end to end, with the real ROS 1 parts (issue 24): a roscore of its own on
127.0.0.1 and a free port, kfd_node with use_sim_time, `rosbag record` of its scan_filtered and
~stats, `rosbag play --clock` of a bag (a prefix of a real log, or a small bag written by
kfd_bench_fast_bag). Then kfd-filter on the same bag: the node's kept scans (stamps, every field,
NaN positions) must be the first N kept scans of kfd-filter's output, N what the node kept, and
the node's final ~stats must count every scan played (scans_in = the /scan messages the recorder
saw = the bag's scans in the prefix: no message lost).
Everything the test starts runs in its own process group and is killed at the end of each test,
on failure, on SIGTERM/SIGINT and at exit.
Usage: kfd_node_live_test.py BUILD_APPS_DIR DATASETS_DIR FAST_BAG_EXE"""
import os
import subprocess
import sys
import time
import unittest

import kfd_ros1_harness as harness  # test/support/python (PYTHONPATH: test/CMakeLists.txt)


class KfdNodeLive(harness.LiveHarness):
    def test_fast_bag_40hz_matches_kfd_filter(self):
        exe = harness.FAST_BAG_EXE
        if not exe or not os.access(exe, os.X_OK):
            self.skipTest("no bag writer (kfd_bench_fast_bag: Google Benchmark missing)")
        bag = os.path.join(self.tmp, "fast.bag")
        subprocess.run([exe, bag, "none", "6", "40", "1081", "270", "0.01"], check=True)
        self.check(bag)

    def test_aces_prefix_matches_kfd_filter(self):
        self.check(self.dataset("aces/aces.orig.bag"), seconds=60, rate=4)

    def test_intel_prefix_matches_kfd_filter(self):
        self.check(self.dataset("intel/intel.orig.bag"), seconds=60, rate=4)

    def test_fr079_prefix_matches_kfd_filter(self):
        self.check(self.dataset("fr079/fr079.orig.bag"), seconds=60, rate=4)

    def test_aces_prefix_next_scan_matches_kfd_filter(self):
        """~next_scan: true: each keyframe one scan later, the same scans as kfd-filter's with
        next_scan = true, the last one too (published when the node is stopped by SIGINT)."""
        # A file with the one key: kfd's defaults with next_scan = true, what the node runs with
        # ~next_scan and no ~config (the node and kfd-filter must agree scan for scan).
        ini = os.path.join(self.tmp, "next.ini")
        with open(ini, "w") as f:
            f.write("[KFD]\nnext_scan = true\n")
        kept, _ = self.check(self.dataset("aces/aces.orig.bag"), seconds=30, rate=4,
                             node_args=["_next_scan:=true"], filter_args=["-c", ini])
        self.assertEqual(len(kept), self.ref_count)

    def fast_bag(self, seconds="6"):
        exe = harness.FAST_BAG_EXE
        if not exe or not os.access(exe, os.X_OK):
            self.skipTest("no bag writer (kfd_bench_fast_bag: Google Benchmark missing)")
        bag = os.path.join(self.tmp, "fast.bag")
        subprocess.run([exe, bag, "none", seconds, "40", "1081", "270", "0.01"], check=True,
                       stdout=subprocess.DEVNULL)
        return bag

    def held_keyframe_on_stop(self, how):
        """Issue 38: stopped `how` (stop_node), the node publishes the keyframe held for its
        next scan (~next_scan) and the last ~stats that count it: every scan kfd-filter keeps."""
        # The fast bag's 120 scans, a keyframe at least every 17th: the last one (119 = 7 x 17)
        # is a keyframe, held when the node is stopped.
        ini = os.path.join(self.tmp, "next.ini")
        with open(ini, "w") as f:
            f.write("[KFD]\n[KFD.evidence_denoise]\nnext_scan = true\n"
                    "[KFD.view_keyframe]\nmax_consecutive_drops = 16\n")
        kept, _ = self.check(self.fast_bag("3"), odom="none", stop=how,
                             node_args=["_config:=" + ini], filter_args=["-c", ini])
        self.assertEqual(len(kept), self.ref_count)
        self.assertIn("stopping (1 held keyframe published)", self.log_of("kfd_node"))

    def test_sigint_publishes_the_held_keyframe(self):
        self.held_keyframe_on_stop("int")

    def test_sigterm_publishes_the_held_keyframe(self):
        self.held_keyframe_on_stop("term")

    def test_rosnode_kill_publishes_the_held_keyframe(self):
        self.held_keyframe_on_stop("kill")

    def test_a_stop_ends_a_long_wait_for_odometry(self):
        """Issue 38: with ~tf_wait:=10 a scan that waits for a transform that never comes does
        not hold SIGINT up (it took 9.4 s): one scan without scan_time (so the node cannot bound
        the wait by the scan's pace), the bag's clock stopped after it."""
        import rosbag
        one = os.path.join(self.tmp, "one.bag")
        with rosbag.Bag(self.fast_bag("1")) as src, rosbag.Bag(one, "w") as dst:
            for topic, m, t in src.read_messages(topics=["/scan"]):
                m.scan_time = 0.0
                dst.write(topic, m, t)
                break
        self.master.setParam("/kfd_test", "/use_sim_time", True)
        node = self.start("kfd_node", [self.node_exe, "__name:=kfd_node", "_odom:=tf",
                                       "_tf_wait:=10"])
        self.wait_for(lambda: "/kfd_node" in self.graph()[1].get("/scan", []), 30,
                      lambda: "kfd_node to subscribe: " + self.log_of("kfd_node"))
        play = self.start("play", ["rosbag", "play", "--clock", "-q", "-d", "1", one])
        play.wait(timeout=60)
        time.sleep(1.0)  # the scan waits: 10 s of a stopped clock, at most 20 s of wall time
        start = time.monotonic()
        self.stop_node(node, "int")
        self.assertLess(time.monotonic() - start, 3.0, self.log_of("kfd_node"))
        self.assertIn("stopping (0 held keyframes published)", self.log_of("kfd_node"))

    def test_ccny_laser_only_bag_matches_kfd_filter(self):
        self.check(self.dataset("ccny-urg/demo.bag"), rate=4, odom="none")


class KfdNodeHelp(unittest.TestCase):
    def test_help_answers_without_a_master(self):
        """Issue 38: `kfd_node --help` tried to reach a master and hung, deaf to SIGINT."""
        exe = os.path.join(harness.APPS, "kfd_node")
        if not os.access(exe, os.X_OK):
            self.skipTest("kfd_node not built: " + exe)
        env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % harness.free_port())
        for flag in ("--help", "-h"):
            r = subprocess.run([exe, flag], env=env, capture_output=True, text=True, timeout=10)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("usage: kfd_node", r.stdout)
            self.assertIn("~odom (tf | topic | none)", r.stdout)


if __name__ == "__main__":
    harness.APPS = os.path.abspath(sys.argv[1])
    harness.DATASETS = os.path.abspath(sys.argv[2]) if len(sys.argv) > 2 and sys.argv[2] else ""
    harness.FAST_BAG_EXE = (os.path.abspath(sys.argv[3])
                            if len(sys.argv) > 3 and sys.argv[3] else "")
    unittest.main(argv=sys.argv[:1] + sys.argv[4:], verbosity=2)  # skips: test.sh lists them
