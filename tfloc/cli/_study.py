"""What ``tfloc bench STUDY.toml`` runs around a run: the steps a study file declares (the verbs
that make its tables, run as their commands would) and the scaling study.

A step is a verb of this command line applied to the run: ``index`` (tf-global's place index of
every global dataset's map, before the run), ``timing`` (the side-by-side timing pass; with
``--quick`` one scan per stratum and a contended pass kept, marked; otherwise a pass still
contended after its retries stops the study with its one-line error, the run kept), ``verdict``
(the truth-free verdict of its sequences), ``report``,
``robustness``, ``real-note``. Each is the verb itself (``tfloc STEP RUN``), so a table made by ``make bench`` is the table a user gets by hand.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tfloc.harness.config import RunConfig, Study


def step_commands(cfg: RunConfig, step: str, quick: bool) -> list[list[str]]:
    """The command lines (without ``tfloc``) of one step of the run ``cfg``."""
    out = str(cfg.out)
    if step == "index":
        from tfloc.io.scenario import GLOBAL, read_scenario

        return [["index", "--dataset", str(d)] for d in cfg.datasets if read_scenario(d).mode == GLOBAL]
    if step == "timing":
        return [["timing", out, *(["--per-stratum", "1", "--allow-contended"] if quick else [])]]
    return [[step, out]]


def run_steps(cfg: RunConfig, steps: list[str], quick: bool = False) -> None:
    """Run ``steps`` of the run ``cfg`` in order (a failing step raises its one-line error)."""
    from . import build_parser

    parser = build_parser()
    for step in steps:
        for words in step_commands(cfg, step, quick):
            print(f"tfloc {' '.join(words)}", file=sys.stderr)
            args = parser.parse_args(words)
            code = int(args._run(args) or 0)
            if code:
                print(f"tfloc {' '.join(words)}: exit {code}", file=sys.stderr)


def run_scaling_study(study: Study, args: argparse.Namespace) -> int:
    """The scaling study a study file of ``kind = "scaling"`` declares (its ``[scaling]`` table:
    the study configuration's fields, and ``quick``), then its figure and README."""
    from .scaling import run_config

    table = dict(study.scaling)
    quick = bool(table.pop("quick", False)) or args.quick
    out = args.out or study.out
    return run_config(table, quick, Path(out), regenerate=args.regenerate, progress=args.progress,
                      command=f"tfloc bench {study.path}")
