"""Check a recording for faults a tracker suffers from: odometry that stalls, jumps or is missing,
gaps in the scan stream, empty scans; with --poses, stretches of a trajectory the map does not
cover. Computed from the recording alone (stamps, odometry increments, ranges; no truth), each
rule's threshold relative to the recording's own statistics (docs/data.md lists them).

Prints one line per flagged stretch (kind, scans, seconds, message) and a one-line summary; exits
0 when the recording is usable (flags or not), 2 with a one-line error where it is not (fewer than
2 scans, no return at all, a start outside the map, rows without odometry).

Example:
  tfloc check-recording data/scenarios/real-csail-native
  tfloc track --dataset data/scenarios/run1 --matcher tf-plus-track --out est.csv
  tfloc check-recording data/scenarios/run1 --poses est.csv
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

HELP = "flag odometry stalls/jumps, scan gaps and unmapped stretches of a recording"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("dataset", type=Path, help="scenario dataset directory (a sequence, or any dataset)")
    p.add_argument("--poses", metavar="truth|odometry|FILE",
                   help="also flag where these poses lie outside the map or the map explains almost no "
                        "return: 'truth' (the rows' true poses), 'odometry' (dead reckoning from the "
                        "start), or a CSV with scan_id,est_x,est_y,est_theta (tfloc track --out)")
    p.add_argument("--limit", type=int, default=0, help="print at most N flags (default: all)")


def run(args: argparse.Namespace) -> int:
    from tfloc.evaluation.recording import check_recording, coverage_flags
    from tfloc.io.scenario import check_usable, map_for, read_scans, read_scenario

    scenario = read_scenario(args.dataset)
    scans = read_scans(scenario)
    the_map = map_for(scenario, scans[0]) if scans else None
    check_usable(scenario, scans, the_map)
    check = check_recording(scans, scenario.laser)
    flags = list(check.flags)
    if args.poses:
        flags += coverage_flags(the_map, scenario.laser, scans, _poses(args.poses, scans))
        flags.sort(key=lambda f: f.first)
    shown = flags[:args.limit] if args.limit > 0 else flags
    for f in shown:
        print(f.line())
    if len(shown) < len(flags):
        print(f"… {len(flags) - len(shown)} more")
    extra = len(flags) - len(check.flags)
    cover = f"; {extra} coverage flag(s) for --poses {args.poses}" if args.poses else ""
    print(f"{scenario.name}: {check.summary()}{cover}; usable")
    return 0


def _poses(which: str, scans: list) -> list:
    """The poses ``--poses`` names, one per scan (None where unknown)."""
    if which == "truth":
        return [s.true for s in scans]
    if which == "odometry":
        from tfloc.harness.track import odom_deltas

        if scans[0].initial is None or any(s.odom is None for s in scans):
            from tfloc.errors import DatasetError

            raise DatasetError("--poses odometry needs a sequence (a start pose and odometry on every row)")
        p, out = scans[0].initial, []
        for d in odom_deltas(scans):
            p = p.compose(d)
            out.append(p)
        return out
    from tfloc.core.pose import Pose
    from tfloc.errors import ResultsError
    from tfloc.io.text import csv_rows

    ids = {s.scan_id: k for k, s in enumerate(scans)}
    out: list = [None] * len(scans)
    _, rows = csv_rows(which, ResultsError, "estimates file", ("scan_id", "est_x", "est_y", "est_theta"))
    for line, row in rows:
        k = ids.get((row["scan_id"] or "").strip())
        if k is None:
            raise ResultsError(f"{which}:{line}: scan_id {row['scan_id']!r} is not a scan of the dataset")
        try:
            p = Pose(*(float(row[c]) for c in ("est_x", "est_y", "est_theta")))
        except (TypeError, ValueError):
            raise ResultsError(f"{which}:{line}: est_x/est_y/est_theta are not numbers") from None
        out[k] = p if all(math.isfinite(v) for v in p.as_array()) else None
    return out
