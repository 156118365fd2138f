#!/usr/bin/python3
"""kfd_node live benchmark (issue 24; not a test): plays (a) a simulated 1081-beam, 270-degree,
40 Hz bag (kfd_bench_fast_bag, with a 200 Hz IMU, multi-echo scans and 50 Hz odometry beside it)
at its rate and (b) the first SECONDS of the Freiburg bags at 10x their rate into kfd_node with
use_sim_time, each against its own roscore on 127.0.0.1, and prints a Markdown table: scans
played and seen by the node (lost = the difference), scans kept and how many of them kfd-filter
keeps too, the node's per-scan latency p50/p99/max from its ~stats (subscriber callback entry
to publish return, the wait for the scan's odometry included) and kfd's own work (from the
odometry in hand to publish return), and the node's CPU share (user + sys from /proc/PID/stat
over the playing time / that wall time). The 40 Hz bag three times (odometry from /tf waited
for, `_tf_wait:=0`: the newest transform, `_odom:=none`: laser only), aces twice. Same harness
as the live test (test/support/python/kfd_ros1_harness.py).
Usage: PYTHONPATH=test/support/python scripts/bench/ros_bench.py BUILD_DIR [DATASETS_DIR [SECONDS]]"""
import os
import sys

try:
    import kfd_ros1_harness as live  # test/support/python/kfd_ros1_harness.py
except ImportError:
    sys.exit("%s: the live harness is not importable: run it with "
             "PYTHONPATH=test/support/python" % sys.argv[0])


def run(bag, play_args, node_args, seconds=None):
    tc = live.LiveHarness(methodName="run_live")
    tc.setUp()
    try:
        if seconds:  # the first `seconds` of scans, odometry 2 s longer (as in the live test)
            bag = tc.prefix(bag, float(seconds))
        odom = [a[len("_odom:="):] for a in node_args if a.startswith("_odom:=")] or ["tf"]
        kept, stats, played, ref = tc.run_live(bag, node_args, play_args,
                                               ["--odom-topic", odom[0]])
        cpu, wall = tc.node_cpu
        mine = {m.header.stamp.to_nsec() for m in kept}
        theirs = {m.header.stamp.to_nsec() for m in ref}
        return {"played": len(played), "in": int(stats["scans_in"]), "kept": len(kept),
                "same": len(mine & theirs), "ref": len(theirs),
                "p50": float(stats["latency_p50_us"]), "p99": float(stats["latency_p99_us"]),
                "max": float(stats["latency_max_us"]), "w50": float(stats["work_p50_us"]),
                "w99": float(stats["work_p99_us"]), "wmax": float(stats["work_max_us"]),
                "cpu": 100.0 * cpu / wall, "wall": wall}
    finally:
        tc.doCleanups()


def main():
    build = os.path.abspath(sys.argv[1])
    datasets = os.path.abspath(sys.argv[2]) if len(sys.argv) > 2 else ""
    seconds = sys.argv[3] if len(sys.argv) > 3 else "200"
    live.APPS = os.path.join(build, "apps")
    tmp = live.tempfile.mkdtemp(prefix="kfd_ros_bench_")
    fast = os.path.join(tmp, "fast40.bag")
    live.subprocess.run([os.path.join(build, "test", "bench", "kfd_bench_fast_bag"), fast, "none",
                         "60", "40", "1081", "270", "0.01"], check=True)
    cases = [("simulated 1081 beams, 40 Hz, 60 s, odometry from /tf", fast, [], [], None),
             ("the same, `_tf_wait:=0` (newest transform)", fast, [], ["_tf_wait:=0"], None),
             ("the same, `_odom:=none` (laser only)", fast, [], ["_odom:=none"], None)]
    for name in ("aces", "intel", "fr079"):
        bag = os.path.join(datasets, name, name + ".orig.bag")
        if os.path.isfile(bag):
            cases.append(("%s, first %s s at 10x" % (name, seconds), bag,
                          ["-r", "10"], [],
                          seconds))
            if name == "aces":
                cases.append(("aces, the same with `_tf_wait:=0` (newest transform)", bag,
                              ["-r", "10"], ["_tf_wait:=0"], seconds))
        else:
            print("skipped %s: %s missing" % (name, bag), file=sys.stderr)
    print("| bag | scans played | seen by node (lost) | kept (of them kfd-filter's / kfd-filter "
          "kept) | latency p50 / p99 / max (us) | kfd's work p50 / p99 / max (us) "
          "| node CPU (user+sys / wall) |")
    print("|---|---|---|---|---|---|---|")
    for label, bag, play_args, node_args, secs in cases:
        r = run(bag, play_args, node_args, secs)
        print("| %s | %d | %d (%d) | %d (%d / %d) | %.0f / %.0f / %.0f | %.0f / %.0f / %.0f "
              "| %.1f %% of %.1f s |" % (
                  label, r["played"], r["in"], r["played"] - r["in"], r["kept"], r["same"],
                  r["ref"], r["p50"], r["p99"], r["max"], r["w50"], r["w99"], r["wmax"],
                  r["cpu"], r["wall"]), flush=True)
    live.shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
