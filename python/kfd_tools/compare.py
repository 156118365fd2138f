"""kfd-compare: repeated, paired ICP-SLAM runs that tell signal from noise.

For logs x configs x modes x R repeats it runs kfd-icp-slam, then reports per (log, config,
mode) n, median, IQR and mean +- std over the runs of: the relations error split into local
(relations spanning at most S s) and long, ATE (when a ground-truth trajectory exists), drop %,
process CPU time (user + sys of kfd-icp-slam, from the kernel) and CPU per scan; and paired
comparisons (runs matched by repeat): every mode against a baseline mode and named pairs, with
wins / losses / ties, the two-sided exact sign test, the exact Wilcoxon signed-rank test and the
median ratio with a seeded bootstrap 95 % interval. Lower is better for every metric. It
judges them (report.py): failed runs per mode (did not finish, or an error above F x the
baseline's median), the worst run of each mode, a verdict per pair (better / worse / no
significant difference, at which CPU ratio), a warning when there are too few runs for any
p < 0.05, and the reason of every "–".

Repeat K (0 ... R-1) skips the first K scans of the log (kfd-icp-slam --skip-scans K): the same
problem, a different run of a chaotic estimator. A simulated log (sim:WORLD:SENSOR:SPEED) is
also simulated again with seed K + 1.

  kfd-compare run --logs intel aces --modes none kfd odometry@kfd --repeats 20 --out OUT
  kfd-compare run ... --emit-jobs jobs.txt      # one shell command per line, then:
  parallel -j 8 < jobs.txt                       # (or xargs -P, a Slurm array), then:
  kfd-compare collect OUT       # summary.md, report.md, runs.csv, runs.json, plots/
  kfd-compare diagnose OUT --modes kfd odometry@kfd   # where the drops cost: diagnose.md
  kfd-compare configs OUT --mode kfd --configs A.ini B.ini   # one mode, two configs: configs.md
  kfd-compare curve OUT --reference none@A --key max_view_change   # every config vs one: curve.md

Logs: a dataset folder name under --datasets (NAME/NAME.rawlog with NAME.relations) or a path
to any log kfd-icp-slam reads: a .rawlog, a ROS 1 bag or a CARMEN log (NAME.relations and
NAME.gt.tum beside it are used when present; for aces.orig.bag also aces.relations), or
sim:WORLD:SENSOR:SPEED[:DURATION] (kfd-simulate; ground truth .gt.tum). Modes: any of
`kfd-icp-slam --list-modes`, with `@MODE` to drop as many scans as MODE does on the same run
(odometry@kfd, decimate@kfd) and `+lo` for a laser-only run (no odometry to the pre-filter or
to ICP-SLAM: kfd+lo, decimate@kfd+lo).
"""
import argparse
import concurrent.futures
import csv
import hashlib
import io
import json
import math
import os
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time

from . import diagnose as kfd_diagnose
from . import report as kfd_report
from . import stats as kfd_stats

# The package is python/kfd_tools in the source tree (tools in build/apps) or, installed,
# DATADIR/kfd/python/kfd_tools (tools in the prefix's bin, else on PATH).
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
if os.path.isfile(os.path.join(ROOT, "CMakeLists.txt")):
    DEFAULT_EXE = os.path.join(ROOT, "build", "apps", "kfd-icp-slam")
    DEFAULT_SIM = os.path.join(ROOT, "build", "apps", "kfd-simulate")
    DEFAULT_DATASETS = os.path.normpath(os.path.join(ROOT, "..", "shared", "datasets"))
    DEFAULT_CONFIG = os.path.join(ROOT, "share", "kfd-icp-slam", "sick-180-5hz.ini")
else:
    _DATADIR = os.path.dirname(ROOT)

    def _installed_tool(name):
        beside = os.path.join(os.path.dirname(_DATADIR), "bin", name)
        return beside if os.access(beside, os.X_OK) else shutil.which(name) or name

    DEFAULT_EXE = _installed_tool("kfd-icp-slam")
    DEFAULT_SIM = _installed_tool("kfd-simulate")
    DEFAULT_DATASETS = "datasets"
    DEFAULT_CONFIG = os.path.join(_DATADIR, "kfd-icp-slam", "sick-180-5hz.ini")
# An emitted job runs the launcher that ran this (scripts/kfd-compare, bin/kfd-compare), else
# this module with this interpreter (the package then has to be importable where jobs run).
JOB_COMMAND = ([os.environ["KFD_COMPARE_LAUNCHER"]] if os.environ.get("KFD_COMPARE_LAUNCHER")
               else [sys.executable, "-m", "kfd_tools.compare"])
MAX_DT = {"mit-killian": 0.22}  # estimated stamps (its PROVENANCE.md)
METRICS = kfd_report.METRICS  # (metric key, label, unit): what every table and plot reports


class CompareError(Exception):
    pass


# --- logs, modes, jobs ----------------------------------------------------------------------
MAX_REPEATS = 1000  # runs per log, config and mode
MAX_JOBS = 4096     # runs at a time

# The logs kfd-icp-slam reads (by content; these extensions mark a spec as a path).
LOG_EXTENSIONS = (".rawlog", ".bag", ".clf", ".log", ".clf.gz", ".log.gz", ".db3", ".mcap")


class Interrupted(Exception):
    """A run stopped by Ctrl-C or SIGTERM (or not started for it): recorded as interrupted, not
    failed; collect leaves it out of every verdict and a rerun completes it."""


# Ctrl-C / SIGTERM: no new run starts, the running ones get SIGINT (kfd-icp-slam stops cleanly).
_STOP = threading.Event()
_RUNNING = set()
_RUNNING_LOCK = threading.Lock()


def interrupt_running():
    _STOP.set()
    with _RUNNING_LOCK:
        for p in _RUNNING:
            try:
                p.send_signal(signal.SIGINT)
            except OSError:
                pass


def log_stem(filename):
    """aces.orig.bag -> aces.orig; intel.clf.gz -> intel."""
    for ext in sorted(LOG_EXTENSIONS, key=len, reverse=True):
        if filename.endswith(ext):
            return filename[:-len(ext)]
    return filename


def resolve_log(spec, datasets):
    """A log spec -> dict(name, kind, rawlog, relations, gt, max_dt, sim settings)."""
    if spec.startswith("sim:"):
        parts = spec.split(":")[1:]
        if not 1 <= len(parts) <= 4:
            raise CompareError("bad simulated log '%s' (sim:WORLD:SENSOR:SPEED[:DURATION])" % spec)
        world, sensor, speed, duration = parts + ["office", "mit", "0.752", ""][len(parts):]
        return {"name": "sim-%s-%s-%s" % (world, sensor, speed) + ("-%ss" % duration
                                                                   if duration else ""),
                "kind": "sim", "world": world, "sensor": sensor, "speed": speed,
                "duration": duration, "max_dt": 1e-3}
    if spec.endswith(LOG_EXTENSIONS) or os.path.sep in spec:
        rawlog = os.path.abspath(spec)
        name = log_stem(os.path.basename(rawlog))
    else:
        rawlog = os.path.abspath(os.path.join(datasets, spec, spec + ".rawlog"))
        name = spec
    if os.path.isdir(rawlog) and os.path.isfile(os.path.join(rawlog, "metadata.yaml")):
        name = os.path.basename(rawlog.rstrip(os.path.sep))  # a rosbag2 folder
    elif not os.path.isfile(rawlog):
        if spec == name and not os.path.isdir(datasets):
            raise CompareError(
                "log not found: %s: a dataset name is looked up as DATASETS/%s/%s.rawlog, and "
                "the datasets folder %s does not exist (the Freiburg logs with their .relations "
                "are not part of kfd: put them there, or give --datasets DIR, or a log's path)"
                % (spec, spec, spec, datasets))
        raise CompareError("log not found: %s (%s)" % (spec, rawlog))
    # NAME.relations / NAME.gt.tum beside the log: for aces/aces.orig.bag, aces.orig.* or aces.*
    folder = os.path.dirname(rawlog)
    stems = [name, name.split(".")[0]]  # name is the log's file name without its extension

    def beside(ext):
        return next((p for p in (os.path.join(folder, x + ext) for x in stems)
                     if os.path.isfile(p)), None)
    return {"name": name, "kind": "file", "rawlog": rawlog, "relations": beside(".relations"),
            "gt": beside(".gt.tum"),
            "max_dt": MAX_DT.get(stems[1], MAX_DT.get(name, 1e-3))}


def parse_mode(spec):
    """'decimate@kfd+lo' -> ('decimate', 'kfd', True)."""
    laser = spec.endswith("+lo")
    base = spec[:-3] if laser else spec
    mode, _, match = base.partition("@")
    if not mode:
        raise CompareError("bad mode '%s'" % spec)
    if match and mode not in ("odometry", "decimate"):
        raise CompareError("'%s': only odometry and decimate can match another mode's drop rate"
                           % spec)
    return mode, match or None, laser


def check_modes(exe, specs):
    out = subprocess.run([exe, "--list-modes"], check=True, capture_output=True, text=True).stdout
    known = [line.split("\t")[0] for line in out.splitlines() if line.strip()]
    for s in specs:
        mode, match, _ = parse_mode(s)
        for m in [mode] + ([match] if match else []):
            if m not in known:
                raise CompareError("unknown mode '%s' in '%s' (kfd-icp-slam --list-modes: %s)"
                                   % (m, s, ", ".join(known)))


def config_tag(config):
    return os.path.basename(config)[:-len(".ini")] if config.endswith(".ini") \
        else os.path.basename(config)


def run_dir(out, log_name, config, mode, repeat):
    return os.path.join(out, "runs", log_name, config_tag(config), mode, "r%02d" % repeat)


def job_args(a, log, config, mode, repeat):
    args = JOB_COMMAND + [
        "job", "--out", os.path.abspath(a.out), "--log", absolute_log(log),
        "--datasets", os.path.abspath(a.datasets), "--config", os.path.abspath(config),
        "--mode", mode, "--repeat", str(repeat), "--exe", os.path.abspath(a.exe),
        "--sim-exe", os.path.abspath(a.sim_exe), "--split-seconds", repr(a.split_seconds)]
    if a.maps:
        args.append("--map")
    return args + source_args(a)


def absolute_log(spec):
    """A log spec that names a file or folder, made absolute (a job may run from anywhere);
    dataset names and sim: specs as they are."""
    return os.path.abspath(spec) if os.path.exists(spec) else spec


def inputs_of(cmd):
    """What a run's result depends on besides its command: size, mtime and, for the files a
    user edits (configs), a hash of every existing file the command names (the executable,
    the config, the log, its ground truth). A finished run is reused only when these match."""
    out = {}
    for c in cmd:
        if not os.path.isfile(c):
            continue
        st = os.stat(c)
        entry = {"size": st.st_size, "mtime_ns": st.st_mtime_ns}
        if c.endswith((".ini", ".yaml", ".yml", ".cfg")):
            with open(c, "rb") as f:
                entry["sha256"] = hashlib.sha256(f.read()).hexdigest()
        out[c] = entry
    return out


def source_args(a):
    """kfd-icp-slam's bag flags given to kfd-compare (every log of the run gets them)."""
    out = []
    for flag in ("scan_topic", "odom_topic"):
        if getattr(a, flag, None):
            out += ["--" + flag.replace("_", "-"), getattr(a, flag)]
    return out


def simulated_log(a, log, repeat):
    """The simulated log of one repeat (seed repeat + 1), generated once and shared by modes."""
    folder = os.path.join(a.out, "logs", log["name"])
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, "seed%02d.rawlog" % (repeat + 1))
    if not os.path.exists(path):  # kfd-simulate renames complete files into place
        cmd = [a.sim_exe, "-o", path, "-w", log["world"], "-s", log["sensor"], "-v",
               log["speed"], "--seed", str(repeat + 1), "-q"]
        if log["duration"]:
            cmd += ["-d", log["duration"]]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return path, path[:-len(".rawlog")] + ".gt.tum"


def read_json(path):
    with open(path) as f:
        return json.load(f)


def write_run(done, run):
    """run.json, complete or absent (an atomic rename)."""
    os.makedirs(os.path.dirname(done), exist_ok=True)
    tmp = done + ".tmp"
    with open(tmp, "w") as f:
        json.dump(run, f, indent=1)
    os.replace(tmp, done)


def run_failed(done, ident, error, command, **more):
    """Record a run that did not finish (run.json with finished: false, counted as a failed run
    by collect), then raise CompareError(error)."""
    write_run(done, dict(ident, finished=False, error=error, command=command, **more))
    raise CompareError("%s on %s %s r%d\n  %s" % (
        error, ident["log"], ident["mode"], ident["repeat"],
        " ".join(shlex.quote(c) for c in command)))


def reusable(done, cmd):
    """The finished run recorded in `done` when it ran this command on the same inputs
    (inputs_of), else None: a run of an edited config, another binary or another log of the
    same name runs again (and says so)."""
    if not os.path.exists(done):
        return None
    try:
        previous = read_json(done)
    except (OSError, ValueError):
        return None  # an unreadable record: run again
    if not previous.get("finished", True):
        return None
    if previous.get("command") == cmd and previous.get("inputs") == inputs_of(cmd):
        return previous
    print("[kfd-compare] %s: the recorded run's command or inputs (config, binary, log) "
          "changed: running it again" % os.path.dirname(done), file=sys.stderr, flush=True)
    return None


def run_job(a):
    """One kfd-icp-slam run: writes run.json (the summary, kernel CPU times, the command) into
    its run folder; a folder that already holds the run.json of a finished run is kept
    (resume). A run that fails gets a run.json with finished: false and its error (kept for
    collect; run again on resume) and raises CompareError."""
    log = resolve_log(a.log, a.datasets)
    mode, match, laser = parse_mode(a.mode)
    folder = run_dir(a.out, log["name"], a.config, a.mode, a.repeat)
    done = os.path.join(folder, "run.json")
    rawlog, rel, gt = log.get("rawlog"), log.get("relations"), log.get("gt")
    ident = {"log": log["name"], "config": config_tag(a.config), "mode": a.mode,
             "repeat": a.repeat, "seed": a.repeat + 1 if log["kind"] == "sim" else None,
             "skip_scans": a.repeat}
    if log["kind"] == "sim":
        try:
            rawlog, gt = simulated_log(a, log, a.repeat)
        except subprocess.CalledProcessError as e:
            run_failed(done, ident, "kfd-simulate failed (exit %d)" % e.returncode, e.cmd)
    cmd = [a.exe, a.config, rawlog, "-o", folder, "-m", mode, "-q", "--skip-scans",
           str(a.repeat), "--split-seconds", repr(a.split_seconds)] + source_args(a)
    if not a.map:
        cmd.append("--no-map")
    if rel:
        cmd += ["-g", rel]
    if gt:
        cmd += ["--gt", gt]
    if rel or gt:
        cmd += ["--max-dt", repr(log["max_dt"])]
    if match:
        cmd += ["--match-drop-of", match]
    if laser:
        cmd.append("--laser-only")
    previous = reusable(done, cmd)
    if previous:
        return previous
    os.makedirs(os.path.dirname(folder), exist_ok=True)
    t0 = time.monotonic()
    with open(folder + ".stderr", "w") as err:
        with _RUNNING_LOCK:
            if _STOP.is_set():
                raise Interrupted("not started")
            # A session of its own: a Ctrl-C reaches kfd-compare, which stops its runs itself.
            p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err,
                                 start_new_session=True)
            _RUNNING.add(p)
        try:
            _, status, ru = os.wait4(p.pid, 0)
        finally:
            with _RUNNING_LOCK:
                _RUNNING.discard(p)
        p.returncode = os.waitstatus_to_exitcode(status)  # reaped here, not by Popen
    wall = time.monotonic() - t0
    code = p.returncode
    if code != 0 and (_STOP.is_set() or code in (130, 143, -signal.SIGINT, -signal.SIGTERM)):
        write_run(done, dict(ident, finished=False, interrupted=True, command=cmd,
                             error="interrupted (exit %d)" % code))
        raise Interrupted("%s %s r%d" % (ident["log"], ident["mode"], ident["repeat"]))
    if code != 0:
        with open(folder + ".stderr") as f:
            msg = f.read().strip().splitlines()
        if code == 1 and msg and "skipped at its start" in msg[0]:
            # Repeat K skips K scans: beyond the log's scans it is not a run at all (neither
            # recorded nor failed), but a request to make smaller.
            os.remove(folder + ".stderr")
            raise CompareError("%s has no scan left after skipping %d: --repeats %d asks for "
                               "more repeats than the log has scans (repeat K skips K scans)"
                               % (ident["log"], a.repeat, a.repeat + 1))
        how = "exit %d" % code if code > 0 else "killed by signal %d" % -code
        run_failed(done, ident, "kfd-icp-slam failed (%s): %s" % (
            how, msg[0] if msg else "no message"), cmd, exit_code=code, wall_s=wall,
            stderr=os.path.relpath(folder + ".stderr", a.out))
    os.remove(folder + ".stderr")
    s = read_json(os.path.join(folder, "summary.json"))

    def trans(key):
        r = s.get(key)
        return r.get("trans_mean_m") if r else None

    cpu = ru.ru_utime + ru.ru_stime - s.get("cpu_s_match", 0.0)
    run = dict(ident, **{
        "local": trans("relations_local"), "long": trans("relations_long"),
        "all": trans("relations"), "ate": s.get("ate_rmse_m"), "drop": s["dropped_pct"],
        "cpu": cpu, "cpu_ms_per_scan": 1e3 * cpu / max(1, s["scans_in"]),
        "cpu_user_s": ru.ru_utime, "cpu_sys_s": ru.ru_stime,
        "cpu_match_s": s.get("cpu_s_match", 0.0), "wall_s": wall,
        "scans_in": s["scans_in"], "scans_kept": s["scans_kept"],
        "relations_local_used": (s.get("relations_local") or {}).get("used"),
        "relations_long_used": (s.get("relations_long") or {}).get("used"),
        "target_drop_pct": s.get("target_drop_pct"), "laser_only": s.get("laser_only"),
        "icp_rejected": s.get("icp_rejected"), "lost_tracks": s.get("lost_tracks_suspected"),
        "finished": True, "command": cmd, "inputs": inputs_of(cmd)})
    write_run(done, run)
    return run


def what_is_judged(log, modes, baseline):
    """One line per log, said before the runs: what its verdict rests on."""
    if log["kind"] == "sim":
        return "%s: simulated, ground-truth trajectory: judged on ATE" % log["name"]
    if log.get("relations"):
        return "%s: relations %s: judged on the local and long relations error" % (
            log["name"], os.path.basename(log["relations"]))
    if log.get("gt"):
        return "%s: ground-truth trajectory %s: judged on ATE" % (
            log["name"], os.path.basename(log["gt"]))
    if baseline not in modes:
        return ("%s: no ground truth and no %s runs: no verdict on accuracy (add mode %s), "
                "only CPU, drop rate, ICP rejections and lost tracks" % (
                    log["name"], baseline, baseline))
    return ("%s: no ground truth (no .relations or .gt.tum beside it): accuracy is judged "
            "against %s's own spread between repeats (trajectory ATE and drift per metre), "
            "with ICP rejections, lost tracks and the CPU ratio; nothing says which is closer to "
            "the truth" % (log["name"], baseline))


def icp_configs(a):
    """The configs of a run: --configs, or with --icp both each one and its twin with the other
    ICP schedule (X.ini and X-every-scan.ini, e.g. sick-180-5hz.ini: ICP after 0.2 m / 5 deg of
    odometry; sick-180-5hz-every-scan.ini: ICP on every scan)."""
    if a.icp == "given":
        return a.configs
    out = []
    for c in a.configs:
        gated = c[:-len("-every-scan.ini")] + ".ini" if c.endswith("-every-scan.ini") else c
        every = gated[:-len(".ini")] + "-every-scan.ini"
        wanted = {"both": [gated, every], "every-scan": [every], "gated": [gated]}[a.icp]
        for w in wanted:
            if not os.path.isfile(w):
                raise CompareError("--icp %s: no %s beside %s" % (a.icp, w, c))
            if w not in out:
                out.append(w)
    return out


def say_what_is_judged(a):
    """Before any run: per log what its verdict rests on; per config its ICP schedule."""
    if a.quiet:
        return
    for log in a.logs:
        print("[kfd-compare] " + what_is_judged(resolve_log(log, a.datasets), a.modes,
                                                a.baseline), file=sys.stderr)
    for c in a.configs:
        print("[kfd-compare] %s: %s (CPU ratios hold for this ICP config; --icp both runs "
              "both schedules)" % (config_tag(c), kfd_report.icp_schedule_of(c)), file=sys.stderr)


def plan(a):
    """Every job of a run command, as (log, config, mode, repeat), repeat by repeat: a run cut
    short still has every log, config and mode, with fewer repeats."""
    for log in a.logs:
        resolve_log(log, a.datasets)  # fail early on a missing log
    return [(log, config, mode, k) for k in range(a.repeats) for log in a.logs
            for config in a.configs for mode in a.modes]


def unique_tags(a):
    """Each log and config gets its own folder under runs/: two configs (or logs) whose names
    would share one are refused, naming them."""
    tags = {}
    for c in a.configs:
        other = tags.setdefault(config_tag(c), c)
        if os.path.abspath(other) != os.path.abspath(c):
            raise CompareError("two configs share the name %s (%s, %s): their runs would share "
                               "one folder; rename one" % (config_tag(c), other, c))
    names = {}
    for log in a.logs:
        name = resolve_log(log, a.datasets)["name"]
        other = names.setdefault(name, log)
        if absolute_log(other) != absolute_log(log):
            raise CompareError("two logs share the name %s (%s, %s): their runs would share "
                               "one folder; rename one" % (name, other, log))


def cmd_run(a):
    if not 1 <= a.repeats <= MAX_REPEATS:
        raise CompareError("--repeats must be in [1, %d], not %d" % (MAX_REPEATS, a.repeats))
    if not 1 <= a.jobs <= MAX_JOBS:
        raise CompareError("--jobs must be in [1, %d], not %d" % (MAX_JOBS, a.jobs))
    a.configs = icp_configs(a)
    for c in a.configs:
        if not os.path.isfile(c):
            raise CompareError("config not found: " + c)
    if not os.access(a.exe, os.X_OK):
        raise CompareError("kfd-icp-slam not found: %s (build it: bash scripts/test.sh)"
                           % a.exe)
    check_modes(a.exe, a.modes)
    unique_tags(a)
    jobs = plan(a)
    say_what_is_judged(a)
    if a.emit_jobs:
        with open(a.emit_jobs, "w") as f:
            for j in jobs:
                f.write(" ".join(shlex.quote(x) for x in job_args(a, *j)) + "\n")
        print("[kfd-compare] %d jobs written to %s; run them (e.g. parallel -j N < %s), then "
              "kfd-compare collect %s" % (len(jobs), a.emit_jobs, a.emit_jobs, a.out),
              file=sys.stderr)
        return 0
    t0 = time.monotonic()
    failed = []

    def one(j):
        log, config, mode, k = j
        ns = argparse.Namespace(out=a.out, log=log, datasets=a.datasets, config=config,
                                mode=mode, repeat=k, exe=a.exe, sim_exe=a.sim_exe,
                                split_seconds=a.split_seconds, map=a.maps,
                                scan_topic=a.scan_topic, odom_topic=a.odom_topic)
        return run_job(ns)

    def on_term(*_):
        raise KeyboardInterrupt
    old_term = signal.signal(signal.SIGTERM, on_term)
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs)
    futures = {pool.submit(one, j): j for j in jobs}
    try:
        for n, fut in enumerate(concurrent.futures.as_completed(futures), 1):
            j = futures[fut]
            try:
                fut.result()
            except Interrupted:
                pass  # recorded in its run.json; counted by stop_runs
            except (CompareError, subprocess.CalledProcessError) as e:
                failed.append((j, str(e)))
            if not a.quiet:
                el = time.monotonic() - t0
                print("[kfd-compare] %d/%d %s %s %s r%02d  (%.0f s, eta %.0f s)" % (
                    n, len(jobs), j[0], config_tag(j[1]), j[2], j[3], el,
                    el / n * (len(jobs) - n)), file=sys.stderr, flush=True)
    except KeyboardInterrupt:
        return stop_runs(a, pool, futures)
    finally:
        signal.signal(signal.SIGTERM, old_term)
    pool.shutdown()
    for j, e in failed:
        print("[kfd-compare] failed: %s" % e, file=sys.stderr)
    collect(a.out, a.baseline, a.pairs, a.plots, a.quiet, a.failure_factor)
    return 1 if failed else 0


def stop_runs(a, pool, futures):
    """Ctrl-C or SIGTERM during `run`: the queue stops, the running runs are stopped and
    recorded as interrupted, the report is made of what finished. Exit status 130."""
    print("[kfd-compare] interrupted: stopping the running runs (they are recorded as "
          "interrupted, not failed; run the same command again to complete them)",
          file=sys.stderr, flush=True)
    for f in futures:
        f.cancel()
    interrupt_running()
    pool.shutdown(wait=True)
    stopped = sum(1 for f in futures if f.cancelled() or isinstance(f.exception(), Interrupted))
    done = sum(1 for f in futures if not f.cancelled() and f.exception() is None)
    bad = sum(1 for f in futures if not f.cancelled() and isinstance(
        f.exception(), (CompareError, subprocess.CalledProcessError)))
    print("[kfd-compare] %d runs finished, %d failed, %d interrupted or not started" % (
        done, bad, stopped), file=sys.stderr, flush=True)
    if done:
        try:
            collect(a.out, a.baseline, a.pairs, a.plots, a.quiet, a.failure_factor)
        except CompareError as e:
            print("[kfd-compare] %s" % e, file=sys.stderr)
    return 130


# --- collect ---------------------------------------------------------------------------------

def load_runs(out):
    """Every run under OUT/runs: its run.json (a finished run, or the record of one that
    failed), and for a job that stopped before writing one (its rKK.stderr left, no run.json) a
    record with finished: false; collect counts both kinds as failed runs."""
    runs = []
    base = os.path.join(out, "runs")
    if not os.path.isdir(base):
        raise CompareError("no runs under %s (run kfd-compare run first)" % base)
    for dirpath, _, files in os.walk(base):
        if "run.json" in files:
            runs.append(read_run(base, dirpath, out))
        for name in files:
            if name.endswith(".stderr") and not os.path.exists(
                    os.path.join(dirpath, name[:-len(".stderr")], "run.json")):
                runs.append(unfinished_run(base, dirpath, name, out))
    if not runs:
        raise CompareError("no finished run under " + base)
    runs.sort(key=lambda r: (r["log"], r["config"], r["mode"], r["repeat"]))
    return runs


def read_run(base, dirpath, out):
    """A run folder's run.json, or, when it cannot be read (empty, cut short, not JSON), a
    record with finished: false saying so (counted as a failed run)."""
    path = os.path.join(dirpath, "run.json")
    try:
        run = read_json(path)
        if isinstance(run, dict) and all(k in run for k in ("log", "config", "mode", "repeat")):
            return run
        why = "not a run record"
    except (OSError, ValueError) as e:
        why = str(e) or type(e).__name__
    log, config, mode, folder = os.path.relpath(dirpath, base).split(os.sep)[-4:]
    repeat = int(folder[1:]) if folder[1:].isdigit() else -1
    return {"log": log, "config": config, "mode": mode, "repeat": repeat, "skip_scans": repeat,
            "finished": False, "error": "unreadable run.json (%s): %s" % (
                why, os.path.relpath(path, out))}


def unfinished_run(base, dirpath, name, out):
    """The record of a job that left runs/LOG/CONFIG/MODE/rKK.stderr and no run.json."""
    log, config, mode = os.path.relpath(dirpath, base).split(os.sep)
    repeat = int(name[1:-len(".stderr")])
    return {"log": log, "config": config, "mode": mode, "repeat": repeat, "skip_scans": repeat,
            "finished": False, "stderr": os.path.relpath(os.path.join(dirpath, name), out),
            "error": "no run.json: the job stopped before kfd-icp-slam finished (or is still "
                     "running)"}


fmt = kfd_report.fmt  # the report's number formats
fmt_p = kfd_report.fmt_p
RUN_COLUMNS = ["log", "config", "mode", "repeat", "seed", "skip_scans"] + \
    [m for m, _, _ in METRICS] + \
    ["cpu_user_s", "cpu_sys_s", "cpu_match_s", "wall_s", "scans_in", "scans_kept",
     "relations_local_used", "relations_long_used", "target_drop_pct", "laser_only",
     "icp_rejected", "lost_tracks", "finished", "failed", "failure", "folder"]


def collect(out, baseline="none", pairs=None, plots=True, quiet=False,
            failure_factor=kfd_report.FAILURE_FACTOR):
    """report.md, summary.md, runs.csv and runs.json (and plots/) of the runs under OUT."""
    if not failure_factor > 0:
        raise CompareError("--failure-factor must be > 0 (got %g)" % failure_factor)
    runs = load_runs(out)
    # Interrupted runs (Ctrl-C) are neither finished nor failed: left out of every verdict.
    interrupted = [r for r in runs if r.get("interrupted")]
    runs = [r for r in runs if not r.get("interrupted")]
    if not runs:
        raise CompareError("only interrupted runs under %s: run kfd-compare run again to "
                           "complete them" % os.path.join(out, "runs"))
    groups, stats = kfd_report.analyse(runs, baseline,
                                       [tuple(x.split(":", 1)) for x in pairs or []],
                                       failure_factor, lambda r: run_trajectory(out, r))
    stats["interrupted"] = [{k: r.get(k) for k in ("log", "config", "mode", "repeat")}
                            for r in interrupted]
    table = io.StringIO(newline="")
    w = csv.DictWriter(table, fieldnames=RUN_COLUMNS, extrasaction="ignore")
    w.writeheader()
    for r in runs:
        w.writerow(r)
    if plots:
        for g in groups:
            plot(out, g.log, g.config, g.modes, baseline)
    note = ("%d interrupted run(s) left out (kfd-compare run again completes them).\n\n" %
            len(interrupted) if interrupted else "")
    write_all({os.path.join(out, "runs.csv"): table.getvalue(),
               os.path.join(out, "runs.json"): json.dumps(stats, indent=1),
               os.path.join(out, "summary.md"): note + kfd_report.summary_md(groups, stats),
               os.path.join(out, "report.md"): note + kfd_report.report_md(groups, stats, out,
                                                                           plots)})
    if not quiet:
        failed = sum(1 for r in runs if r["failed"])
        print("[kfd-compare] %d runs (%d failed%s): %s, %s, %s, %s" % (
            len(runs), failed, ", %d interrupted left out" % len(interrupted) if interrupted
            else "", os.path.join(out, "summary.md"), os.path.join(out, "report.md"),
            os.path.join(out, "runs.csv"), os.path.join(out, "runs.json")), file=sys.stderr)
    return stats


def write_all(files):
    """Writes {path: text} complete or not at all: every file to PATH.tmp first, then each
    renamed over its path; when one cannot be written (a full disk), the temporary files are
    removed and the old files stay as they were, all of them (CompareError)."""
    written = []
    try:
        for path, text in files.items():
            written.append(path + ".tmp")
            with open(path + ".tmp", "w", newline="") as f:
                f.write(text)
    except OSError as e:
        for tmp in written:
            try:
                os.remove(tmp)
            except OSError:
                pass
        raise CompareError("cannot write %s (%s): the reports in %s are left as they were" % (
            written[-1][:-len(".tmp")], e.strerror or e, os.path.dirname(written[-1])))
    for path in files:
        os.replace(path + ".tmp", path)


def run_trajectory(out, r):
    """A finished run's trajectory.tum as (t, x, y, yaw) poses, or None."""
    path = os.path.join(out, kfd_report.run_folder(r), "trajectory.tum")
    return kfd_diagnose.read_tum(path) if os.path.isfile(path) else None


def plot(out, log, config, modes, baseline):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    order = sorted(modes, key=lambda m: (m != baseline, m))
    shown = [(m, label, unit) for m, label, unit in METRICS
             if m in ("local", "long", "ate", "cpu") and any(
                 r.get(m) is not None for mode in order for r in modes[mode].values())]
    if not shown:
        return
    fig, axes = plt.subplots(1, len(shown), figsize=(4.2 * len(shown), 3.6), squeeze=False)
    for ax, (m, label, unit) in zip(axes[0], shown):
        data = [[r[m] for r in modes[mode].values() if r.get(m) is not None] for mode in order]
        ax.boxplot(data, labels=order, showfliers=True)
        ax.set_title("%s (%s)" % (label, unit), fontsize=9)
        ax.tick_params(axis="x", labelrotation=45, labelsize=7)
        ax.tick_params(axis="y", labelsize=7)
        if m != "cpu" and all(v > 0 for d in data for v in d):
            ax.set_yscale("log")
    n = max(len(modes[m]) for m in order)
    fig.suptitle("%s, %s: %d repeats per mode" % (log, config, n), fontsize=10)
    fig.tight_layout()
    os.makedirs(os.path.join(out, "plots"), exist_ok=True)
    png = os.path.join(out, "plots", "%s-%s.png" % (log, config))
    fig.savefig(png + ".tmp", dpi=110, format="png")  # complete or absent, as write_all
    os.replace(png + ".tmp", png)
    plt.close(fig)


# --- command line ----------------------------------------------------------------------------

class DefaultsHelpFormatter(argparse.HelpFormatter):
    """Help with each option's default where it has a real one (not for flags, required
    options, or options whose help already says it)."""

    def _get_help_string(self, action):
        h = action.help or ""
        d = action.default
        if (d is None or d is argparse.SUPPRESS or isinstance(d, bool) or action.required
                or "default" in h or not action.option_strings):
            return h
        shown = " ".join(map(str, d)) if isinstance(d, (list, tuple)) else str(d)
        return "%s (default: %s)" % (h, shown or "none")


def compare_configs(out, mode, config_a, config_b):
    """Markdown: MODE under CONFIG_A against MODE under CONFIG_B on every log of OUT, paired by
    repeat (the same start offset): per log and metric the medians, wins/losses of A (lower is
    better) with the sign test's p, and the median ratio A/B with its bootstrap 95 % interval.
    For a change inside the [KFD] section (two .ini files that differ in one key)."""
    a_tag, b_tag = config_tag(config_a), config_tag(config_b)
    runs = [r for r in load_runs(out) if r["mode"] == mode and r.get("finished", True)]
    by = {}
    for r in runs:
        by.setdefault((r["log"], r["config"]), {})[r["repeat"]] = r
    logs = sorted({log for log, _ in by})
    if not any((log, a_tag) in by and (log, b_tag) in by for log in logs):
        raise CompareError("no log has finished '%s' runs under both %s and %s in %s"
                           % (mode, a_tag, b_tag, out))
    lines = ["# %s: %s against %s" % (mode, a_tag, b_tag), "",
             "Paired by repeat; W/L: runs where %s is lower / higher; p: two-sided exact sign "
             "test; ratio: median of per-run ratios %s/%s [bootstrap 95 %%]." % (a_tag, a_tag,
                                                                                b_tag), "",
             "| log | metric | n | median %s | median %s | W/L (p) | ratio [95 %%] |"
             % (a_tag, b_tag), "|---|---|---:|---:|---:|---:|---:|"]
    for log in logs:
        ra, rb = by.get((log, a_tag), {}), by.get((log, b_tag), {})
        for metric in ("local", "long", "all", "cpu"):
            pairs = [(ra[k][metric], rb[k][metric]) for k in sorted(set(ra) & set(rb))
                     if ra[k].get(metric) is not None and rb[k].get(metric) is not None]
            if not pairs:
                continue
            xa, xb = [x for x, _ in pairs], [y for _, y in pairs]
            st = kfd_stats.paired(xa, xb)
            lines.append("| %s | %s | %d | %.3f | %.3f | %d/%d (%.2g) | %.2f [%.2f-%.2f] |" % (
                log, metric, st["n"], kfd_stats.median(xa), kfd_stats.median(xb), st["wins"],
                st["losses"], st["p_sign"], st["median_ratio"], st["ratio_lo"], st["ratio_hi"]))
    return "\n".join(lines) + "\n"


def kfd_key(config_path, key):
    """The value of KEY in a kfd-icp-slam .ini's kfd configuration: in a stage's section
    [KFD.<stage>] (KEY "max_view_change", or "view_keyframe.max_view_change" for that stage's
    only), or as a flat key of before in [KFD]; the last one given, a trailing '# comment' cut.
    None when the file or the key is missing."""
    stage, _, name = key.rpartition(".")
    value, section = None, None
    try:
        lines = open(config_path).read().splitlines()
    except OSError:
        return None
    for line in lines:
        line = line.split("#", 1)[0].strip()
        if line.startswith("[") and line.endswith("]"):
            section = line[1:-1].strip()
        elif section and (section == "KFD" or section.startswith("KFD.")) and "=" in line:
            k, v = line.split("=", 1)
            if k.strip() == name and (not stage or section == "KFD." + stage):
                value = v.strip()
    return value


def compare_curve(out, mode, reference, key=None, factor=kfd_report.FAILURE_FACTOR):
    """Markdown: MODE under every config of OUT against one reference (REF_MODE@CONFIG, e.g.
    none@default: a mode that ignores the [KFD] section, run once), paired by repeat, one table
    per log, a row per config (sorted by name): n, failed runs (report.py's rule, judged against
    the reference's medians), median drop %, and per error the log gives (local and long
    relations error, else ATE) the median, the median of the per-run ratios to the reference and
    W/L with the sign test's p; the median per-run CPU ratio; the worst run. With KEY, a column
    with that [KFD] key's value read from each config's .ini (as the run's command names it).
    For a curve over one [KFD] knob (e.g. max_view_change: the drop rate)."""
    if "@" not in reference:
        raise CompareError("--reference is MODE@CONFIG (e.g. none@default), got '%s'" % reference)
    ref_mode, ref_config = reference.split("@", 1)
    ref_config = config_tag(ref_config)
    by = {}
    for r in load_runs(out):
        by.setdefault((r["log"], r["config"], r["mode"]), {})[r["repeat"]] = r
    logs = sorted({log for log, c, m in by if c == ref_config and m == ref_mode})
    if not logs:
        raise CompareError("no '%s' runs under %s in %s" % (ref_mode, ref_config, out))
    lines = ["# %s against %s (%s), by config" % (mode, ref_mode, ref_config), "",
             "Paired by repeat with %s's runs under %s. ratio: median of the per-run ratios "
             "%s/%s; W/L: runs where %s is lower / higher, p: two-sided exact sign test; CPU: "
             "user+sys; failed: did not finish, or an error above %g x %s's median (the "
             "reference row judges %s's runs the same way); worst: the run with the largest "
             "long error (local without long relations, ATE without relations)."
             % (ref_mode, ref_config, mode, ref_mode, mode, factor, ref_mode, ref_mode), ""]
    for log in logs:
        ref = by[(log, ref_config, ref_mode)]
        configs = sorted(c for l, c, m in by if l == log and m == mode)
        if not configs:
            continue
        groups = [(c, kfd_report.Group(log, c, {mode: by[(log, c, mode)], ref_mode: ref},
                                       ref_mode, factor)) for c in configs]
        judged = groups[0][1].judged
        head = ["config"] + ([key] if key else []) + ["n", "failed", "dropped %"]
        for m in judged:
            head += ["%s (m)" % kfd_report.NAMES[m], "ratio", "W/L (p)"]
        head += ["CPU ratio", "worst run"]
        lines += ["## %s" % log, "", "| " + " | ".join(head) + " |",
                  "|---|" + "---:|" * (len(head) - 2) + "---|"]

        def row(name, g, m_, vs_ref):
            runs = g.mode_runs(m_)
            cells = [name]
            if key:  # the reference row: its mode ignores [KFD]
                cmd = next((r["command"] for r in runs if r.get("command")), []) \
                    if vs_ref else []
                v = kfd_key(cmd[1], key) if len(cmd) > 1 else None
                cells.append(v if v is not None else "–")
            cells += [str(len(runs)), "%d/%d" % (g.failed(m_), len(runs)),
                      fmt(g.summary[m_]["drop"]["median"], 1)]
            for m in judged:
                cells.append(fmt(g.summary[m_][m]["median"]))
                res = g.results.get((m_, ref_mode), {}).get(m) if vs_ref else None
                cells += ["%.2f" % res["median_ratio"], "%d/%d (%s)" % (
                    res["wins"], res["losses"], fmt_p(res["p_sign"]))] if res else ["", ""]
            res = g.results.get((m_, ref_mode), {}).get("cpu") if vs_ref else None
            cells.append("%.2f" % res["median_ratio"] if res else "")
            w = g.worst[m_]
            wk = kfd_report.worst_key(judged)
            cells.append("r%02d %s m" % (w["repeat"], fmt(w[wk])) if w else "–")
            return "| " + " | ".join(cells) + " |"

        first = groups[0][1]
        lines.append(row("%s (%s)" % (ref_mode, ref_config), first, ref_mode, False))
        for c, g in groups:
            lines.append(row(c, g, mode, True))
        lines.append("")
    return "\n".join(lines)


def build_parser():
    """kfd-compare's command line: run, job, collect, diagnose."""
    ap = argparse.ArgumentParser(
        prog="kfd-compare", description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="Exit status: 0 on success, 1 when a run failed or an input is bad, 2 on bad usage.")
    sub = ap.add_subparsers(dest="command", required=True)
    # Every option says what it does and, when it has one, its default (argparse's %(default)s).
    fmt = {"formatter_class": DefaultsHelpFormatter}
    tools = argparse.ArgumentParser(add_help=False)  # how one run is made: run and job
    tools.add_argument("--datasets", default=DEFAULT_DATASETS,
                       help="folder of the named datasets (NAME/NAME.rawlog, .relations); a "
                       "fresh clone expects ../shared/datasets beside it")
    tools.add_argument("--exe", default=DEFAULT_EXE, help="the kfd-icp-slam to run")
    tools.add_argument("--sim-exe", default=DEFAULT_SIM, help="the kfd-simulate for sim: logs")
    tools.add_argument("--split-seconds", type=float, default=10.0, metavar="S",
                       help="relations over at most S s are local, the others long")
    tools.add_argument("--scan-topic", help="bags: kfd-icp-slam --scan-topic (none: automatic)")
    tools.add_argument("--odom-topic",
                       help="bags: kfd-icp-slam --odom-topic TOPIC|tf|none (none: automatic)")
    report = argparse.ArgumentParser(add_help=False)  # how runs are compared: run and collect
    report.add_argument("--baseline", default="none",
                        help="the mode every other is compared with and failures are judged by")
    report.add_argument("--pairs", nargs="*", default=[], metavar="A:B",
                        help="more pairs to compare, mode A against mode B")
    report.add_argument("--failure-factor", type=float, default=kfd_report.FAILURE_FACTOR,
                        metavar="F", help="a run fails when its local or long relations error "
                        "is above F x the baseline's median on its log and config")
    report.add_argument("--no-plots", dest="plots", action="store_false",
                        help="no box plots (plots/*.png)")
    report.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    r = sub.add_parser("run", parents=[tools, report], help="run (or emit) every job, then collect",
                       **fmt)
    r.add_argument("--logs", nargs="+", required=True,
                   help="dataset names, log paths (.rawlog, .bag, .clf), sim:...")
    r.add_argument("--modes", nargs="+", default=["none", "kfd", "odometry@kfd", "keyframe"],
                   help="pre-filter modes (kfd-icp-slam --mode; odometry@M: the odometry filter "
                   "at M's drop rate)")
    r.add_argument("--configs", nargs="+", default=[DEFAULT_CONFIG], help="kfd-icp-slam .ini files")
    r.add_argument("--icp", choices=["given", "gated", "every-scan", "both"], default="given",
                   help="which ICP schedule of each config: as given, its X.ini (ICP after "
                   "0.2 m / 5 deg of odometry), its X-every-scan.ini (ICP on every scan: where "
                   "a dropped scan saves an ICP run), or both")
    r.add_argument("--repeats", "-R", type=int, default=20,
                   help="runs per log, config and mode (repeat K starts K scans later)")
    r.add_argument("--out", "-o", required=True,
                   help="output folder (runs/, summary.md, report.md, runs.csv); a finished run "
                   "in it is kept (resume)")
    r.add_argument("--jobs", "-j", type=int, default=os.cpu_count() or 1,
                   help="local parallel runs (default: every core)")
    r.add_argument("--emit-jobs", metavar="FILE", help="write one command per line and stop")
    r.add_argument("--maps", action="store_true", help="keep each run's map and map figure")
    j = sub.add_parser("job", parents=[tools], help="one run (what --emit-jobs writes)", **fmt)
    j.add_argument("--out", required=True, help="the comparison's output folder")
    j.add_argument("--log", required=True, help="dataset name, log path or sim:...")
    j.add_argument("--config", required=True, help="kfd-icp-slam .ini file")
    j.add_argument("--mode", required=True, help="pre-filter mode")
    j.add_argument("--repeat", type=int, required=True, help="repeat K: starts K scans later")
    j.add_argument("--map", action="store_true", help="keep the run's map and map figure")
    c = sub.add_parser("collect", parents=[report],
                       help="merge the finished runs of DIR into its report", **fmt)
    c.add_argument("dir", help="a comparison's output folder")
    k = sub.add_parser("configs", help="one mode under two configs, paired by repeat", **fmt)
    k.add_argument("dir", help="a comparison's output folder (run with both configs)")
    k.add_argument("--mode", default="kfd", help="the mode to compare (default: kfd)")
    k.add_argument("--configs", nargs=2, required=True, metavar=("A", "B"),
                   help="the two kfd-icp-slam .ini files (or their names) of the run")
    v = sub.add_parser("curve", help="one mode under every config against one reference run, "
                       "paired by repeat", **fmt)
    v.add_argument("dir", help="a comparison's output folder")
    v.add_argument("--mode", default="kfd", help="the mode whose configs make the rows")
    v.add_argument("--reference", required=True, metavar="MODE@CONFIG",
                   help="the runs every row is paired with (e.g. none@default: a mode that "
                   "ignores [KFD], run under one config)")
    v.add_argument("--key", help="a kfd key whose value (from each config's .ini, [KFD.<stage>] or "
                   "[KFD]) is shown; STAGE.KEY for one stage's")
    v.add_argument("--failure-factor", type=float, default=kfd_report.FAILURE_FACTOR,
                   metavar="F", help="a run fails when an error is above F x the reference's "
                   "median on its log")
    g = sub.add_parser("diagnose", help="gaps between kept scans and the local error they cost",
                       **fmt)
    g.add_argument("dir", help="a comparison's output folder")
    g.add_argument("--modes", nargs="+", required=True, help="modes to diagnose (2 or more)")
    g.add_argument("--reference", default="none", help="mode whose repeat 0 gives the motion")
    g.add_argument("--datasets", default=DEFAULT_DATASETS, help="folder of the named datasets")
    g.add_argument("--split-seconds", type=float, default=10.0, metavar="S",
                   help="relations over at most S s are local")
    return ap


def main(argv=None):
    a = build_parser().parse_args(argv)
    try:
        if a.command == "run":
            return cmd_run(a)
        if a.command == "job":
            parse_mode(a.mode)
            run_job(a)
            return 0
        if a.command == "configs":
            text = compare_configs(a.dir, a.mode, a.configs[0], a.configs[1])
            with open(os.path.join(a.dir, "configs.md"), "w") as f:
                f.write(text)
            sys.stdout.write(text)
            return 0
        if a.command == "curve":
            text = compare_curve(a.dir, a.mode, a.reference, a.key, a.failure_factor)
            with open(os.path.join(a.dir, "curve.md"), "w") as f:
                f.write(text)
            sys.stdout.write(text)
            return 0
        if a.command == "diagnose":
            text = kfd_diagnose.diagnose(a.dir, a.modes, a.reference, a.split_seconds,
                                         a.datasets)
            with open(os.path.join(a.dir, "diagnose.md"), "w") as f:
                f.write(text)
            sys.stdout.write(text)
            return 0
        collect(a.dir, a.baseline, a.pairs, a.plots, a.quiet, a.failure_factor)
        return 0
    except (CompareError, subprocess.CalledProcessError, OSError) as e:
        print("kfd-compare: %s" % e, file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
