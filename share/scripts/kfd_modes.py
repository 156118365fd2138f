"""kfd-icp-slam's pre-filter modes, as the tool itself lists them (`--list-modes`), so the
experiment scripts never keep their own copy of the list."""
import subprocess


def list_modes(exe):
    """Mode names in the tool's order, with kfd first: its drop rate is the target of the
    odometry baseline (--match-drop)."""
    out = subprocess.run([exe, "--list-modes"], check=True, capture_output=True, text=True).stdout
    names = [line.split("\t")[0] for line in out.splitlines() if line.strip()]
    return ["kfd"] + [n for n in names if n != "kfd"] if "kfd" in names else names


def choose(exe, wanted):
    """`wanted` (a list from --modes, or None for every mode), checked against the tool's list
    and put in run order (kfd first)."""
    known = list_modes(exe)
    if not wanted:
        return known
    unknown = [m for m in wanted if m not in known]
    if unknown:
        raise SystemExit("unknown mode(s) %s (kfd-icp-slam --list-modes: %s)"
                         % (", ".join(unknown), ", ".join(known)))
    if "odometry" in wanted and "kfd" not in wanted:
        raise SystemExit("--modes odometry needs kfd too (its drop rate is the target)")
    return [m for m in known if m in wanted]
