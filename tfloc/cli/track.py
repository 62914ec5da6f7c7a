"""Track one sequence dataset with one matcher: each scan localized from the last estimate
composed with the odometry since then (truth not needed: true_* may be empty).

The dataset's scenario.json says "mode": "sequence"; scans.csv has stamp and odom_x/y/theta on
every row and init_x/y/theta on the first (where the robot starts). A matcher that declines a
scan, or raises, keeps the prediction as its estimate, and that row's status says so (failed,
error:<message>); the run goes on, and exits 3 if any row is an error. cpu_s is the CPU time of
each step (this process, every library on one thread). With --matcher odometry the estimates are
the prediction alone (dead reckoning).

Output (--out): scan_id, est_x, est_y, est_theta, status, cpu_s; one row per scan, in order.
Where the dataset has truth, a last line scores the track: the tracked share of the scans with
truth (within 10 cm and 2 deg), APE, losses, jumps > 1 m and the median CPU per step.

--draw-at SCAN_ID (or first-loss: the first scan with truth whose estimate is more than 0.5 m or
10 deg off) looks at the tracker right after that scan's step: --figure PATH draws the map around
the robot, the truth (if known), the prediction, the estimate and the tracker's belief if it
exposes one (AMCL's particles, coloured by weight); --explain prints the step's info and the
belief's weights (effective sample size, the sensor factor at the truth, the estimate and half a
metre off, the spread the motion model added). The snapshot: tfloc/harness/belief.py; its summary: tfloc/evaluation/belief.py; the drawing: tfloc/report/belief.py.

Example:
  tfloc track --dataset data/scenarios/seq-quick --matcher tf-plus --out est.csv
  tfloc track --dataset data/scenarios/real-csail-native --matcher amcl --draw-at first-loss \\
      --figure loss.png --explain
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

from tqdm import tqdm

from tfloc.core.thresholds import Thresholds
from tfloc.errors import ConfigError, ResultsError

HELP = "track a sequence dataset with one matcher (guess = last estimate ⊕ odometry)"
COLUMNS = ["scan_id", "est_x", "est_y", "est_theta", "status", "cpu_s"]
DEFAULT_THRESHOLDS = Thresholds()


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dataset", required=True, type=Path,
                   help="sequence dataset directory (scenario.json with \"mode\": \"sequence\" + scans.csv)")
    p.add_argument("--matcher", default="tf-plus",
                   help="registered matcher name; 'odometry' is dead reckoning (default: tf-plus)")
    p.add_argument("--param", action="append", default=[], metavar="KEY=VALUE",
                   help="a matcher parameter, VALUE in TOML syntax (repeatable)")
    p.add_argument("--out", type=Path, default=Path("est.csv"), help="output CSV (default: est.csv)")
    p.add_argument("--draw-at", metavar="SCAN_ID",
                   help="look at the tracker after this scan's step ('first-loss': the first scan lost)")
    p.add_argument("--figure", type=Path, metavar="PATH",
                   help="with --draw-at: write the picture there (.png, .pdf or .svg)")
    p.add_argument("--explain", action="store_true",
                   help="with --draw-at: print the step's info and the belief's weights")


def run(args: argparse.Namespace) -> int:
    from tfloc.core.tracker import as_tracker
    from tfloc.harness.belief import Watch
    from tfloc.harness.threads import limit_threads
    from tfloc.harness.track import check_sequence, track
    from tfloc.io.scenario import read_scans, read_scenario

    from ._matcher import matcher_from_args

    check_draw_options(args)
    limit_threads(1)
    scenario = read_scenario(args.dataset)
    scans = read_scans(scenario)
    check_sequence(scenario, scans)
    target = draw_target(args.draw_at, scans, scenario.scans_path)
    tracker = as_tracker(matcher_from_args(args.matcher, args.param, "track"))
    watch = Watch(tracker, scans, scenario.laser.angles, target) if target is not None else None
    with tqdm(total=len(scans), desc=args.matcher, unit="scan", disable=not sys.stderr.isatty()) as bar:
        def progress(k: int) -> None:
            bar.update(1)
            if watch is not None:
                watch(k)
        rows = track(scenario, scans, tracker, progress=progress)
    write_track(args.out, rows)
    if watch is not None:
        show(args, watch.result(rows), scenario, scans[0])
    counts: dict[str, int] = {}
    for r in rows:
        counts[r.status.kind.value] = counts.get(r.status.kind.value, 0) + 1
    print(f"wrote {args.out}: {len(rows)} scans; " + ", ".join(f"{k} {v}" for k, v in counts.items()),
          file=sys.stderr)
    line = score_line(rows)
    if line:
        print(line, file=sys.stderr)
    return 3 if counts.get("error") else 0


def score_line(rows: list) -> str:
    """One line scoring the track where the dataset has truth: tracked share of the truth-bearing
    scans, APE, losses and jumps > 1 m, median CPU per step (empty without truth)."""
    from tfloc.evaluation.trajectory import JUMP_M, score_rows

    s = score_rows(rows)
    if s.n_truth == 0:
        return ""
    return (f"score: tracked {100 * s.tracked:.1f} % of {s.n_truth} scans with truth "
            f"({s.n_tracked} within {100 * DEFAULT_THRESHOLDS.dist_m:g} cm and {DEFAULT_THRESHOLDS.orient_deg:g}°); "
            f"APE RMSE {100 * s.ape_rmse_m:.1f} cm; losses {s.losses} ({s.unrecovered} unrecovered); "
            f"jumps > {JUMP_M:g} m {s.jumps}; CPU {s.cpu_ms_median:.2f} ms per step (median)")


def check_draw_options(args: argparse.Namespace) -> None:
    """One line naming the option for a bad combination or file type (before any work)."""
    if args.draw_at is None:
        for given, name in ((args.figure is not None, "--figure"), (args.explain, "--explain")):
            if given:
                raise ConfigError(f"{name} needs --draw-at SCAN_ID (or --draw-at first-loss)")
        return
    if args.figure is None and not args.explain:
        raise ConfigError(f"--draw-at {args.draw_at}: give --figure PATH and/or --explain")
    if args.figure is not None and args.figure.suffix.lower() not in (".png", ".pdf", ".svg"):
        raise ConfigError(f"--figure {args.figure}: the picture's name must end in .png, .pdf or .svg")


def draw_target(draw_at: str | None, scans: list, where: Path) -> int | str | None:
    """The scan index ``--draw-at`` names, :data:`~tfloc.harness.belief.FIRST_LOSS`, or ``None``."""
    from tfloc.harness.belief import FIRST_LOSS

    if draw_at is None:
        return None
    if draw_at == FIRST_LOSS:
        if not any(s.true is not None for s in scans):
            raise ConfigError(f"--draw-at {FIRST_LOSS}: {where} has no truth to tell a loss")
        return FIRST_LOSS
    ids = [str(s.scan_id) for s in scans]
    if draw_at not in ids:
        raise ConfigError(f"--draw-at {draw_at}: no such scan_id in {where} (first {ids[0]}, last {ids[-1]})")
    return ids.index(draw_at)


def show(args: argparse.Namespace, snap, scenario, first_scan) -> None:
    """Print and draw the snapshot ``--draw-at`` asked for (or say that no scan was lost)."""
    from tfloc.io.scenario import map_for
    from tfloc.report.belief import explain, fig_belief

    if snap is None:
        print(f"--draw-at {args.draw_at}: no scan with truth was lost; nothing drawn", file=sys.stderr)
        return
    if args.explain:
        print(f"{args.matcher} on {scenario.name}, " + explain(snap), flush=True)
    if args.figure is not None:
        the_map = map_for(scenario, first_scan, {})
        try:
            fig_belief(snap, the_map, args.figure, f"{args.matcher} on {scenario.name}", scenario.laser.max_range)
        except OSError as exc:
            raise ResultsError(f"--figure {args.figure}: cannot write ({exc.strerror or exc})") from None
        print(f"wrote {args.figure}", file=sys.stderr)


def write_track(path: Path, rows: list) -> None:
    """``est.csv``: :data:`COLUMNS`, one row per scan in order (metres, radians, seconds)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS)
            for r in rows:
                w.writerow([r.scan_id, f"{r.est_x:.6f}", f"{r.est_y:.6f}", f"{r.est_theta:.7f}", str(r.status),
                            "" if r.cpu_s is None else f"{r.cpu_s:.6f}"])
    except OSError as exc:
        raise ResultsError(f"{path}: cannot write ({exc.strerror or exc})") from None
