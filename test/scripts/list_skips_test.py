"""scripts/ci/list-skips.sh (the end of scripts/test.sh): over a hand-made excerpt of ctest's
LastTest.log it lists each test that skipped itself (GoogleTest's GTEST_SKIP, Python unittest's
skipTest) with the reason it gave, says how many, and counts no test that ran."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "ci",
                      "list-skips.sh")

# One gtest skip with its message, one gtest pass, one unittest skip, one unittest pass, and the
# gtest summary lines that repeat a skipped test's name (not counted again).
LOG = """\
1/3 Testing: Simulator.GridmapAndRouteFiles
1/3 Test: Simulator.GridmapAndRouteFiles
Output:
----------------------------------------------------------
[==========] Running 1 test from 1 test suite.
[ RUN      ] Simulator.GridmapAndRouteFiles
/src/test/sim/simulator_test.cpp:174: Skipped
MRPT sample gridmap missing: /usr/share/mrpt/datasets/x.gridmap.gz

[  SKIPPED ] Simulator.GridmapAndRouteFiles (0 ms)
[==========] 1 test from 1 test suite ran. (0 ms total)
[  PASSED  ] 0 tests.
[  SKIPPED ] 1 test, listed below:
[  SKIPPED ] Simulator.GridmapAndRouteFiles
<end of output>
Test Passed.
2/3 Testing: Simulator.CorridorAndGazeboSensor
[ RUN      ] Simulator.CorridorAndGazeboSensor
[       OK ] Simulator.CorridorAndGazeboSensor (12 ms)
[  PASSED  ] 1 test.
Test Passed.
3/3 Testing: kfd_compare_test
test_local_run (__main__.CompareTest.test_local_run) ... ok
test_parallel (__main__.CompareTest.test_parallel) ... skipped 'GNU parallel not installed'

----------------------------------------------------------------------
Ran 2 tests in 3.021s

OK (skipped=1)
Test Passed.
"""


def run(text):
    with tempfile.TemporaryDirectory() as d:
        log = os.path.join(d, "LastTest.log")
        with open(log, "w") as f:
            f.write(text)
        return subprocess.run(["bash", SCRIPT, log], capture_output=True, text=True, check=True)


class ListSkipsTest(unittest.TestCase):
    def test_each_skip_is_listed_with_its_reason_and_counted(self):
        lines = run(LOG).stdout.splitlines()
        self.assertEqual(lines[:2], [
            "  Simulator.GridmapAndRouteFiles: MRPT sample gridmap missing: "
            "/usr/share/mrpt/datasets/x.gridmap.gz",
            "  test_parallel: 'GNU parallel not installed'",
        ])
        self.assertEqual(len(lines), 3, lines)
        self.assertTrue(lines[2].startswith("2 tests skipped (above: why"), lines[2])

    def test_a_run_without_skips_says_so(self):
        passed = LOG.split("3/3 Testing")[0].split("2/3 Testing")[1]
        self.assertEqual(run(passed).stdout, "no test skipped\n")

    def test_one_skip_is_singular_and_a_skip_without_message_says_so(self):
        one = LOG.split("2/3 Testing")[0].replace(
            "MRPT sample gridmap missing: /usr/share/mrpt/datasets/x.gridmap.gz\n", "")
        lines = run(one).stdout.splitlines()
        self.assertEqual(lines[0], "  Simulator.GridmapAndRouteFiles: (no reason given)")
        self.assertTrue(lines[1].startswith("1 test skipped (above: why"), lines[1])

    def test_without_a_log_it_is_a_usage_error(self):
        r = subprocess.run(["bash", SCRIPT], capture_output=True, text=True)
        self.assertEqual(r.returncode, 2)
        self.assertIn("usage", r.stderr)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
