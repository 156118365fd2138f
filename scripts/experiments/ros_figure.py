#!/usr/bin/python3
"""Figure of what kfd_node does between a laser driver and the SLAM (issue 24): runs the real
kfd_node live (its own roscore on 127.0.0.1, use_sim_time, `rosbag play --clock`, `rosbag record`;
the harness of test/support/python/kfd_ros1_harness.py, as scripts/bench/ros_bench.py uses it) on the first
SECONDS (60) of scans of the Freiburg bag fr079 played at 4x, and draws with matplotlib (Agg, no
display):
  top:    a time strip of every /scan message the recorder saw (the driver's scans) and of the
          ones the node passed on (/scan_filtered, its keyframes);
  bottom: the two kept scans in which the node removed the most points, in the robot frame
          (base_link: the laser's mount read from the bag's /tf_static), x forward (up): the raw
          scan's points grey, the points passed on dark blue, the points the node set to NaN red,
          with a 1 m scale bar.
Every count in the titles and legends is measured in this run (the node's ~stats and the
recorded bag). Needs python3-rosbag, python3-matplotlib, ros-core and a build with kfd_node.
Usage: PYTHONPATH=test/support/python scripts/experiments/ros_figure.py BUILD_DIR DATASETS_DIR OUT.png [SECONDS [RATE]]
  e.g. scripts/experiments/ros_figure.py build ../shared/datasets docs/figures/kfd-node-raw-vs-filtered.png"""
import math
import os
import sys

try:
    import kfd_ros1_harness as live  # test/support/python/kfd_ros1_harness.py
except ImportError:
    sys.exit("%s: the live harness is not importable: run it with "
             "PYTHONPATH=test/support/python" % sys.argv[0])

BAG = os.path.join("fr079", "fr079.orig.bag")


def run_node(bag, seconds, rate):
    """Plays the first `seconds` of `bag` at `rate` into kfd_node: (kept scans, final ~stats,
    /scan messages played)."""
    tc = live.LiveHarness(methodName="run_live")
    tc.setUp()
    try:
        prefix = tc.prefix(bag, seconds)
        kept, stats, played, _ = tc.run_live(prefix, [], ["-r", str(rate)])
        return kept, stats, played
    finally:
        tc.doCleanups()


def laser_mount(bag, frame):
    """(x, y, yaw) of `frame` in base_link from the bag's /tf_static (identity if absent)."""
    import rosbag
    with rosbag.Bag(bag) as b:
        for _, m, _ in b.read_messages(topics=["/tf_static"]):
            for tr in m.transforms:
                if tr.child_frame_id.lstrip("/") == frame.lstrip("/"):
                    q = tr.transform.rotation
                    yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
                    return (tr.transform.translation.x, tr.transform.translation.y, yaw,
                            tr.header.frame_id)
    return (0.0, 0.0, 0.0, frame)


def stamp(msg):
    return (msg.header.stamp.secs, msg.header.stamp.nsecs)


def valid(r, scan):
    return math.isfinite(r) and scan.range_min <= r < scan.range_max


def points(scan, ranges, mount, keep):
    """Robot-frame (x, y) of the beams i with keep(i, range)."""
    mx, my, myaw, _ = mount
    xs, ys = [], []
    for i, r in enumerate(ranges):
        if keep(i, r):
            a = myaw + scan.angle_min + i * scan.angle_increment
            xs.append(mx + r * math.cos(a))
            ys.append(my + r * math.sin(a))
    return xs, ys


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    build, datasets, out = (os.path.abspath(a) for a in sys.argv[1:4])
    seconds = float(sys.argv[4]) if len(sys.argv) > 4 else 60.0
    rate = float(sys.argv[5]) if len(sys.argv) > 5 else 4.0
    live.APPS = os.path.join(build, "apps")
    bag = os.path.join(datasets, BAG)
    if not os.path.isfile(bag):
        sys.exit("missing " + bag)

    kept, stats, played = run_node(bag, seconds, rate)
    if not kept:
        sys.exit("the node kept no scan (stats %s)" % stats)
    raw_by_stamp = {stamp(m): m for m in played}
    missing = [k.header.stamp.to_sec() for k in kept if stamp(k) not in raw_by_stamp]
    if missing:
        sys.exit("kept scans with no played /scan of the same stamp: %s" % missing[:5])

    # Per kept scan: points the node removed (NaN now, a valid reading in the driver's scan).
    removed = []
    valid_total = 0
    for k in kept:
        raw = raw_by_stamp[stamp(k)]
        idx = [i for i, (r, f) in enumerate(zip(raw.ranges, k.ranges))
               if valid(r, raw) and math.isnan(f)]
        removed.append(idx)
        valid_total += sum(1 for r in raw.ranges if valid(r, raw))
    removed_total = sum(len(r) for r in removed)
    scans_in, scans_kept = int(stats["scans_in"]), int(stats["scans_kept"])
    if scans_kept != len(kept):
        print("warning: ~stats says %d kept, %d recorded on /scan_filtered" % (scans_kept,
                                                                            len(kept)),
              file=sys.stderr)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter

    t0 = min(m.header.stamp.to_sec() for m in played)
    t_in = [m.header.stamp.to_sec() - t0 for m in played]
    t_kept = [k.header.stamp.to_sec() - t0 for k in kept]
    # The two kept scans with the most removed points, in time order.
    shown = sorted(sorted(range(len(kept)), key=lambda i: -len(removed[i]))[:2])
    mount = laser_mount(bag, kept[0].header.frame_id)

    fig = plt.figure(figsize=(10, 5.6), dpi=100)
    gs = fig.add_gridspec(2, 2, height_ratios=[1.3, 3.6], hspace=0.3, wspace=0.12,
                          left=0.1, right=0.99, top=0.9, bottom=0.07)
    fig.suptitle("kfd_node between the laser driver (/scan) and the SLAM (/scan_filtered): "
                 "fr079, first %.0f s of scans played at %g\u00d7" % (seconds, rate), fontsize=11)

    ax = fig.add_subplot(gs[0, :])
    ax.eventplot([t_kept, t_in], lineoffsets=[0, 1], linelengths=0.75, linewidths=0.8,
                 colors=["#1f3d99", "0.55"])
    ax.eventplot([[t_kept[i] for i in shown]], lineoffsets=[0], linelengths=0.75,
                 linewidths=1.6, colors=["#e01010"])
    for n, i in enumerate(shown):
        ax.annotate("ABCD"[n], (t_kept[i] + 0.25, 0), ha="left", va="center", fontsize=8,
                    color="#c01010", fontweight="bold")
    ax.set_yticks([0, 1])
    ax.set_yticklabels(["/scan_filtered\n%d kept" % scans_kept, "/scan\n%d in" % scans_in],
                       fontsize=8)
    ax.set_ylim(-0.6, 1.5)
    ax.set_xlim(0, max(t_in) + 0.5)
    ax.set_xlabel("bag time (s); one line per scan message", fontsize=8)
    ax.tick_params(axis="x", labelsize=8)
    lost = len(played) - scans_in
    ax.set_title("%d scans in (%d lost), %d passed on (%.0f %%), %d dropped as non-keyframes; "
                 "in the kept scans %d of %d points (%.1f %%) set to NaN"
                 % (scans_in, lost, scans_kept, 100.0 * scans_kept / scans_in,
                    scans_in - scans_kept, removed_total, valid_total,
                    100.0 * removed_total / valid_total), fontsize=8.5)

    # One window for both panels (the same scale): a half disc ahead of the robot, its radius
    # the 90th percentile of the shown scans' point distances (a corridor's far points would
    # shrink everything else); the points outside it are counted in the titles.
    dist = sorted(math.hypot(x, y) for i in shown
                  for x, y in zip(*points(raw_by_stamp[stamp(kept[i])],
                                          raw_by_stamp[stamp(kept[i])].ranges, mount,
                                          lambda j, r, s=raw_by_stamp[stamp(kept[i])]:
                                          valid(r, s))))
    radius = math.ceil(dist[int(0.9 * (len(dist) - 1))]) + 0.5

    def inside(x, y):
        return abs(y) <= radius and -1.0 <= x <= radius

    for n, i in enumerate(shown):
        k = kept[i]
        raw = raw_by_stamp[stamp(k)]
        gone = set(removed[i])
        rx, ry = points(raw, raw.ranges, mount, lambda j, r: valid(r, raw))
        kx, ky = points(raw, k.ranges, mount, lambda j, r: valid(r, raw) and j not in gone)
        gx, gy = points(raw, raw.ranges, mount, lambda j, r: j in gone)
        outside = sum(1 for x, y in zip(rx, ry) if not inside(x, y))
        outside_nan = sum(1 for x, y in zip(gx, gy) if not inside(x, y))
        a = fig.add_subplot(gs[1, n])
        # Forward (x) up, left (+y) to the left: seen from above, the robot facing up.
        a.scatter([-v for v in ry], rx, s=22, c="0.62", lw=0, label="driver's /scan (raw)")
        a.scatter([-v for v in ky], kx, s=3, c="#1f3d99", lw=0,
                  label="passed on in /scan_filtered")
        a.scatter([-v for v in gy], gx, s=18, c="#e01010", lw=0,
                  label="set to NaN by kfd_node (removed as noise)")
        a.plot([0], [0], marker="^", ms=8, c="k", ls="none", label="robot (base_link), facing up")
        a.set_title("%s: kept scan %d of %d, t = %.1f s: %d of %d points set to NaN%s"
                    % ("ABCD"[n], i + 1, len(kept), t_kept[i], len(gx), len(rx),
                       "\n(%d points, %d of them NaN, beyond the frame)" % (outside, outside_nan)
                       if outside else ""), fontsize=8.5)
        a.set_aspect("equal", adjustable="box")
        a.set_xlim(-radius, radius)
        a.set_ylim(-1.0, radius)
        a.tick_params(labelsize=7)
        a.xaxis.set_major_formatter(FuncFormatter(lambda v, _: "%g" % (-v + 0.0)))
        a.set_xlabel("\u2190 left     y (m)     right \u2192", fontsize=8)
        a.set_ylabel("x forward (m)", fontsize=8)
        a.grid(True, lw=0.3, c="0.88")
        a.set_axisbelow(True)
        # 1 m scale bar, bottom right.
        x1, y1 = radius - 0.3, -0.6
        a.plot([x1 - 1.0, x1], [y1, y1], c="k", lw=2.5)
        a.text(x1 - 0.5, y1 + 0.1, "1 m", ha="center", va="bottom", fontsize=8)
        if n == 0:
            handles, labels = a.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, markerscale=1.3,
               frameon=False)
    os.makedirs(os.path.dirname(out) or ".", exist_ok=True)
    fig.savefig(out, dpi=100)
    print("%s: %d scans in, %d kept, %d of %d points set to NaN in the kept scans; shown %s"
          % (out, scans_in, scans_kept, removed_total, valid_total,
             [round(t_kept[i], 2) for i in shown]))


if __name__ == "__main__":
    main()
