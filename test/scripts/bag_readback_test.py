"""A filtered bag read back with Debian's python3-rosbag (an implementation independent of the
C++ rosbag_storage kfd writes with): kfd-filter on a real bag, then every other message must be
in the output byte for byte, the kept scans must be input scans with only removed points
changed (to NaN), and the counts must be the ones kfd-filter printed.
Usage: bag_readback_test.py BUILD_APPS_DIR DATASETS_DIR"""
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

APPS = DATASETS = None


class BagReadback(unittest.TestCase):
    def setUp(self):
        try:
            import rosbag  # noqa: F401
        except ImportError:
            self.skipTest("python3-rosbag not installed")
        self.tmp = tempfile.mkdtemp(prefix="kfd_bag_readback_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def check(self, name, scan_topic="/scan"):
        import rosbag
        src = os.path.join(DATASETS, name)
        if not os.path.isfile(src):
            self.skipTest("dataset missing: " + src)
        out = os.path.join(self.tmp, "out.bag")
        r = subprocess.run([os.path.join(APPS, "kfd-filter"), "-q", "-i", src, "-o", out],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        kept = int(re.search(r"scans +in \d+, kept (\d+)", r.stdout).group(1))
        marked = int(re.search(r"(\d+) removed points written as nan", r.stdout).group(1))
        # the summary says the output's chunk compression, as rosbag reads it (issue 37)
        said = re.search(r"compress +(\w+), as the input", r.stdout).group(1)
        with rosbag.Bag(src) as b, rosbag.Bag(out) as o:
            self.assertEqual(said, o.get_compression_info().compression)
            self.assertEqual(said, b.get_compression_info().compression)

        def others(path):
            with rosbag.Bag(path) as b:
                return sorted((t, m[1], stamp.to_nsec()) for t, m, stamp in
                              b.read_messages(raw=True) if t != scan_topic)
        self.assertEqual(others(src), others(out))

        with rosbag.Bag(src) as b:
            inputs = {(m.header.stamp.to_nsec(), m.header.seq): m
                      for _, m, _ in b.read_messages(topics=[scan_topic])}
        nans = scans = 0
        with rosbag.Bag(out) as b:
            last = None
            for _, m, t in b.read_messages(topics=[scan_topic]):
                scans += 1
                if last is not None:
                    self.assertGreaterEqual(t, last)
                last = t
                orig = inputs[(m.header.stamp.to_nsec(), m.header.seq)]
                self.assertEqual(m.header.frame_id, orig.header.frame_id)
                self.assertEqual((m.angle_min, m.angle_max, m.range_max),
                                 (orig.angle_min, orig.angle_max, orig.range_max))
                self.assertEqual(len(m.ranges), len(orig.ranges))
                for a, b0 in zip(m.ranges, orig.ranges):
                    if math.isnan(a) and not math.isnan(b0):
                        nans += 1
                    else:
                        self.assertEqual(a, b0)
        self.assertEqual(scans, kept)
        self.assertEqual(nans, marked)

    def test_aces_bag_with_odometry_and_tf(self):
        self.check("aces/aces.orig.bag")

    def test_ccny_laser_only_bag(self):
        self.check("ccny-urg/demo.bag")


if __name__ == "__main__":
    APPS, DATASETS = sys.argv[1], sys.argv[2]
    unittest.main(argv=sys.argv[:1], verbosity=2)  # skips with their reason (test.sh lists them)
