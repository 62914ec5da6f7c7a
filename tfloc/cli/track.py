"""Track one sequence dataset with one matcher: each scan localized from the last estimate
composed with the odometry since then (truth not needed: true_* may be empty).

The dataset's scenario.json says "mode": "sequence"; scans.csv has stamp and odom_x/y/theta on
every row and init_x/y/theta on the first (where the robot starts). A matcher that declines a
scan, or raises, keeps the prediction as its estimate, and that row's status says so (failed,
error:<message>); the run goes on, and exits 3 if any row is an error. cpu_s is the CPU time of
each step (this process, every library on one thread). With --matcher odometry the estimates are
the prediction alone (dead reckoning).

Output (--out): scan_id, est_x, est_y, est_theta, status, cpu_s; one row per scan, in order.

Example:
  tfloc track --dataset data/scenarios/seq-quick --matcher tf-plus --out est.csv
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

from tqdm import tqdm

from tfloc.errors import ResultsError

HELP = "track a sequence dataset with one matcher (guess = last estimate ⊕ odometry)"
COLUMNS = ["scan_id", "est_x", "est_y", "est_theta", "status", "cpu_s"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dataset", required=True, type=Path,
                   help="sequence dataset directory (scenario.json with \"mode\": \"sequence\" + scans.csv)")
    p.add_argument("--matcher", default="tf-plus",
                   help="registered matcher name; 'odometry' is dead reckoning (default: tf-plus)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="a matcher parameter, VALUE in TOML syntax (repeatable)")
    p.add_argument("--out", type=Path, default=Path("est.csv"), help="output CSV (default: est.csv)")


def run(args: argparse.Namespace) -> int:
    from tfloc.harness.threads import limit_threads
    from tfloc.harness.track import check_sequence, track
    from tfloc.io.scenario import read_scans, read_scenario

    from ._matcher import matcher_from_args

    limit_threads(1)
    scenario = read_scenario(args.dataset)
    scans = read_scans(scenario)
    check_sequence(scenario, scans)
    matcher = matcher_from_args(args.matcher, args.param, "track")
    with tqdm(total=len(scans), desc=args.matcher, unit="scan", disable=not sys.stderr.isatty()) as bar:
        rows = track(scenario, scans, matcher, progress=lambda _k: bar.update(1))
    write_track(args.out, rows)
    counts: dict[str, int] = {}
    for r in rows:
        kind = r["status"].partition(":")[0]
        counts[kind] = counts.get(kind, 0) + 1
    print(f"wrote {args.out}: {len(rows)} scans; " + ", ".join(f"{k} {v}" for k, v in counts.items()),
          file=sys.stderr)
    return 3 if counts.get("error") else 0


def write_track(path: Path, rows: list[dict]) -> None:
    """``est.csv``: :data:`COLUMNS`, one row per scan in order (metres, radians, seconds)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS)
            for r in rows:
                w.writerow([r["scan_id"], f"{r['est_x']:.6f}", f"{r['est_y']:.6f}",
                            f"{r['est_theta']:.7f}", r["status"], f"{r['cpu_s']:.6f}"])
    except OSError as exc:
        raise ResultsError(f"{path}: cannot write ({exc.strerror or exc})") from None
