"""kfd-compare diagnose on a hand-made output folder: a robot driving 0.1 m per scan along x,
mode `every3` keeping every third scan (0.3 m gaps), mode `burst` keeping two scans in a row
then dropping four (0.1 and 0.5 m gaps), an estimate equal to the truth except a 0.2 m jump."""
import math
import os
import shutil
import subprocess
import tempfile
import unittest

from kfd_tools import diagnose as kfd_diagnose

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
COMPARE = os.path.join(ROOT, "scripts", "kfd-compare")

N = 60


def write_run(folder, kept, x_of):
    os.makedirs(folder)
    with open(os.path.join(folder, "scans.csv"), "w") as f:
        # kfd-icp-slam's scans.csv (the per-scan columns of kfd/io/scan_csv.h)
        f.write("index,timestamp,sensor,kept,reason,p_common,p_threshold,references,points_in,"
                "removed_range,clusters,noise_clusters,removed_noise,points_out,microseconds,"
                "view_change,changed_fraction,degeneracy,corridor,denoise_bound,odometry_check,icp_goodness,odom_x,odom_y,"
                "odom_phi,x,y,phi\n")
        for i in range(N):
            f.write("%d,%.6f,LASER,%d,r,0,0,0,10,0,0,0,0,10,1,0,0,1,0,none,none,,,,,%f,0,0\n"
                    % (i, 100 + 0.2 * i, kept(i), x_of(i)))
    with open(os.path.join(folder, "trajectory.tum"), "w") as f:
        f.write("# timestamp x y z qx qy qz qw\n")
        for i in range(N):
            f.write("%.6f %f 0 0 0 0 0 1\n" % (100 + 0.2 * i, x_of(i)))


class Diagnose(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="kfd_diagnose_test_")
        base = os.path.join(self.tmp, "out", "runs", "line", "cfg")
        truth = lambda i: 0.1 * i  # noqa: E731
        write_run(os.path.join(base, "none", "r00"), lambda i: 1, truth)
        write_run(os.path.join(base, "every3", "r00"), lambda i: int(i % 3 == 0), truth)
        # burst: the estimate jumps 0.2 m after scan 30
        write_run(os.path.join(base, "burst", "r00"), lambda i: int(i % 6 < 2),
                  lambda i: 0.1 * i + (0.2 if i > 30 else 0.0))
        ds = os.path.join(self.tmp, "datasets", "line")
        os.makedirs(ds)
        with open(os.path.join(ds, "line.relations"), "w") as f:
            for i in range(0, N - 5, 5):  # 1 s relations: 0.5 m forward
                f.write("%.6f %.6f 0.5 0 0 0 0 0\n" % (100 + 0.2 * i, 100 + 0.2 * (i + 5)))
        self.out, self.ds = os.path.join(self.tmp, "out"), os.path.join(self.tmp, "datasets")

    def tearDown(self):
        shutil.rmtree(self.tmp)

    def test_gaps_and_error_by_gap(self):
        base = os.path.join(self.out, "runs", "line", "cfg")
        ref = kfd_diagnose.Nearest(kfd_diagnose.read_tum(
            os.path.join(base, "none", "r00", "trajectory.tum")), 1e-3)
        rel = kfd_diagnose.read_relations(os.path.join(self.ds, "line", "line.relations"))
        e = kfd_diagnose.diagnose_mode(base, "every3", ref, rel, 10.0, 1e-3)
        self.assertEqual(len(e["gaps_t"]), 19)
        for g in e["gaps_t"]:
            self.assertAlmostEqual(g, 0.3, places=6)
        self.assertEqual(e["still"], 0)
        self.assertEqual(e["drops"], 40)
        self.assertEqual(sorted(e["by_bin"][("trans", 0.3)]), [0.0] * 11)  # exact estimate
        b = kfd_diagnose.diagnose_mode(base, "burst", ref, rel, 10.0, 1e-3)
        self.assertAlmostEqual(min(b["gaps_t"]), 0.1, places=6)
        self.assertAlmostEqual(max(b["gaps_t"]), 0.5, places=6)
        errs = b["by_bin"][("trans", 0.3)]
        self.assertEqual(len(errs), 11)
        self.assertAlmostEqual(max(errs), 0.2, places=6)  # the relation across the jump
        self.assertEqual(sum(1 for x in errs if x > 1e-9), 1)

    def test_command_writes_diagnose_md(self):
        r = subprocess.run([COMPARE, "diagnose", self.out, "--modes", "every3", "burst",
                            "--datasets", self.ds], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.out, "diagnose.md")) as f:
            text = f.read()
        self.assertEqual(text, r.stdout)
        self.assertIn("## line, cfg", text)
        self.assertIn("| every3 | 1 | 0.300 / 0.300 / 0.300 / 0.30 |", text)
        self.assertIn("trans 0.3+ m", text)

    def test_missing_folder_is_a_clear_error(self):
        r = subprocess.run([COMPARE, "diagnose", os.path.join(self.tmp, "nothing"), "--modes",
                            "kfd"], capture_output=True, text=True)
        self.assertEqual(r.returncode, 1)
        self.assertIn("kfd-compare:", r.stderr)


if __name__ == "__main__":
    unittest.main()
