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

    def test_ccny_laser_only_bag_matches_kfd_filter(self):
        self.check(self.dataset("ccny-urg/demo.bag"), rate=4, odom="none")


if __name__ == "__main__":
    harness.APPS = os.path.abspath(sys.argv[1])
    harness.DATASETS = os.path.abspath(sys.argv[2]) if len(sys.argv) > 2 and sys.argv[2] else ""
    harness.FAST_BAG_EXE = (os.path.abspath(sys.argv[3])
                            if len(sys.argv) > 3 and sys.argv[3] else "")
    unittest.main(argv=sys.argv[:1], verbosity=2)  # skips with their reason (test.sh lists them)
