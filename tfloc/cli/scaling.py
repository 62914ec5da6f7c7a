"""The scaling study: how every matcher's CPU per scan grows with the map's area, the scanner's
beam count and the initial offset, and what each map's preparation costs → OUT/README.md.

Axes (every matcher on the same scans at every level): map area (the office floor
data/maps/office-1.geojson tiled to about 300, 1 200, 5 000 and 20 000 m², as a vector map and
as a 5 cm grid; the scans lie in the first tile, so only the map grows), beam count (181, 361,
721 and 1081 beams) and the initial distance offset (the protocol's bins 0-1, 1-2, 2-3 m).

Measured as the timing pass measures (tfloc timing): one process pinned to one core, every
library on one thread, each matcher's prepare timed with the memory it keeps, an untimed
warm-up, then every scan's localize timed by the harness's timer (CPU time; wall and system
time beside it), matchers interleaved scan by scan with the order rotated. A matcher whose
median exceeds the budget at a level (or whose preparation exceeds its budget) is not run at
the larger levels of that axis. Trackers without a single-scan mode, odometry and the global
matchers are left out unless named (a tracker without a single-scan mode always is).

OUT is a run directory: run.json (kind scaling: the configuration and its fingerprint, package
versions, git commit and dirty flag, machine, each session's start and end, the levels done),
the raw rows scaling.csv, prep.csv and skips.csv (written after every level), then levels.csv,
slopes.csv, scaling.png and README.md. Run again after an interruption, the same command resumes
at the first level not done; on a complete study it only redraws the tables, figure and README.
A directory holding a study of another configuration is refused (exit 2) with one line naming
what differs: give --regenerate to start it over, or another --out.

Examples:
  tfloc scaling --out results/scaling   # the full study (make scaling)
  tfloc scaling --quick --out results/scaling-quick   # 9 scans per level (make scaling-quick)
  tfloc scaling --quick --out /tmp/s --matchers tf-plus,o3d-icp --axes area --areas 300,5000
"""

from __future__ import annotations

import argparse
import shlex
import sys
from dataclasses import replace
from pathlib import Path

from ._options import add_progress

HELP = "the scaling study: CPU per scan against map area, beam count and offset (README.md)"


def _list(kind):
    def parse(text: str) -> tuple:
        try:
            return tuple(kind(v.strip()) for v in text.split(",") if v.strip())
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected comma-separated {kind.__name__} values, got {text!r}") from None
    return parse


OVERRIDES = {  # option → (StudyConfig field, type, help)
    "--matchers": ("matchers", _list(str), "comma-separated registered matcher names (default: every "
                   "registered single-scan local matcher)"),
    "--axes": ("axes", _list(str), "comma-separated axes among area, beams, offset (default: all)"),
    "--areas": ("areas_m2", _list(float), "comma-separated map areas, m² (default 300,1200,5000,20000)"),
    "--kinds": ("kinds", _list(str), "comma-separated map kinds of the area axis: vector, grid (default: both)"),
    "--scans": ("scans_per_level", int, "scans per level of the area and beam axes (default 45; --quick 9)"),
    "--scans-per-bin": ("scans_per_offset_bin", int, "scans per offset bin (default 30; --quick 9)"),
    "--map": ("map_path", str, "the tile map, GeoJSON with an outline (default data/maps/office-1.geojson)"),
}


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--quick", action="store_true",
                   help="the make-bench subsample: every axis and level, 9 scans per level and per offset "
                        "bin, budgets 150 ms per scan and 60 s of preparation (full: 250 ms, 120 s)")
    p.add_argument("--out", type=Path, help="output directory (default: results/scaling, with --quick "
                   "results/scaling-quick)")
    for opt, (_, kind, text) in OVERRIDES.items():
        p.add_argument(opt, type=kind, default=None, help=text)
    p.add_argument("--regenerate", action="store_true",
                   help="if OUT holds a complete study, or one of another configuration, discard it and run "
                        "again (an interrupted study of the same configuration is still resumed)")
    add_progress(p)


def config_from_args(args: argparse.Namespace):
    """The study's configuration: the full or quick one, with the options given."""
    from tfloc.harness.scaling_config import StudyConfig

    cfg = StudyConfig.quick() if args.quick else StudyConfig()
    given = {field: getattr(args, opt[2:].replace("-", "_")) for opt, (field, _, _) in OVERRIDES.items()}
    return replace(cfg, **{k: v for k, v in given.items() if v is not None})


def command_of(args: argparse.Namespace, out: Path) -> str:
    """The command line that makes this study (recorded in run.json and the README)."""
    words = ["tfloc", "scaling", *(["--quick"] if args.quick else []), "--out", str(out)]
    for opt in OVERRIDES:
        v = getattr(args, opt[2:].replace("-", "_"))
        if v is not None:
            words += [opt, ",".join(f"{x:g}" if isinstance(x, float) else str(x) for x in v)
                      if isinstance(v, tuple) else str(v)]
    return shlex.join(words)


def run(args: argparse.Namespace) -> int:
    from dataclasses import asdict

    from tfloc.harness.scaling import StudyConfig

    cfg = config_from_args(args)
    base = asdict(StudyConfig.quick() if args.quick else StudyConfig())
    table = {k: v for k, v in asdict(cfg).items() if v != base[k]}
    out = args.out or Path("results") / ("scaling-quick" if args.quick else "scaling")
    return run_config(table, args.quick, out, args.regenerate, args.progress, command_of(args, out))


def run_config(table: dict, quick: bool, out: Path, regenerate: bool = False, progress: bool | None = None,
               command: str = "") -> int:
    """Run (or resume) the study with the fields ``table`` over the full or quick configuration
    (:meth:`StudyConfig.from_dict`), then render its README and figure from the run directory
    (``tfloc scaling`` and a study file of kind scaling alike)."""
    from tqdm import tqdm

    from tfloc.harness.scaling import StudyConfig, derive_scaling, scaling_study
    from tfloc.report.scaling import render

    cfg = StudyConfig.from_dict(table, StudyConfig.quick() if quick else StudyConfig())
    bar = tqdm(unit="scan", desc="scaling", disable=None if progress is None else not progress,
               smoothing=0.05, mininterval=1.0)

    def step(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.n)

    try:
        rd = scaling_study(cfg, out, regenerate=regenerate, progress=step,
                           log=lambda s: tqdm.write(s, file=sys.stderr), command=command)
    finally:
        bar.close()
    rows, prep, skips, levels, slopes = derive_scaling(rd.path)
    render(rd.path, rows, prep, skips, levels, slopes, rd.info())
    if len(slopes):
        print(slopes[["axis", "kind", "matcher", "slope", "first_ms", "last_ms"]].to_string(
            index=False, float_format=lambda v: f"{v:.2f}"), file=sys.stderr)
    print(f"scaling: {rd.path / 'README.md'}", file=sys.stderr)
    return 0
