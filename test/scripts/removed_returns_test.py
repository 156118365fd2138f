"""scripts/experiments/removed_returns.py on hand-made CARMEN logs: three scans of a wall 2 m
ahead (the robot still), the middle one with a return at 1 m where the others see the wall. Removing that
return is "seen_through"; removing a wall return is "repeated"; a return whose neighbours have
none there is "unknown"; the kept returns' sample and the totals add up."""
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                      "experiments", "removed_returns.py")
BEAMS = 11  # 180 degrees, 18 degrees per beam


def wall():
    return [2.0] * BEAMS


def flaser(ranges, stamp):
    return "FLASER %d %s 0 0 0 0 0 0 %.6f host %.6f\n" % (
        len(ranges), " ".join("%g" % r for r in ranges), stamp, stamp)


def clf(scans):
    head = "PARAM robot_front_laser_max 30\nPARAM laser_front_laser_resolution 18\n"
    return head + "".join(flaser(r, 1.0 + 0.2 * k) for k, r in enumerate(scans))


class RemovedReturns(unittest.TestCase):
    def run_script(self, raw, filtered):
        with tempfile.TemporaryDirectory() as d:
            paths = []
            for name, text in (("raw.clf", raw), ("out.clf", filtered)):
                paths.append(os.path.join(d, name))
                with open(paths[-1], "w") as f:
                    f.write(text)
            r = subprocess.run([sys.executable, SCRIPT] + paths, capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        rows = {}
        for line in r.stdout.splitlines()[3:]:
            cells = [c.strip() for c in line.strip("|").split("|")]
            rows[cells[0]] = int(cells[1])
        return r.stdout.splitlines()[0], rows

    def test_each_removed_return_gets_the_verdict_of_its_neighbours(self):
        middle = wall()
        middle[5] = 1.0  # a return in the middle scan only, in front of the wall
        before, after = wall(), wall()
        before[2] = after[2] = 0.0  # no return there before or after (a dropout)
        raw = clf([before, middle, after])
        out = list(middle)
        out[5] = 0.0  # removed: the neighbours saw the wall behind it
        out[8] = 0.0  # removed: the neighbours have the wall there too
        out[2] = 0.0  # removed: the neighbours have nothing there
        first, rows = self.run_script(raw, flaser(out, 1.2))  # kfd kept the middle scan
        self.assertIn("%d valid returns in 1 kept scans, 3 removed" % BEAMS, first)
        self.assertEqual(rows, {"repeated": 1, "seen_through": 1, "unknown": 1})

    def test_nothing_removed_nothing_counted(self):
        raw = clf([wall(), wall(), wall()])
        first, rows = self.run_script(raw, raw)
        self.assertIn("0 removed", first)
        self.assertEqual(rows, {"repeated": 0, "seen_through": 0, "unknown": 0})


if __name__ == "__main__":
    unittest.main()
