"""What ``tfloc bench STUDY.toml`` runs around a run: the steps a study file declares (the verbs
that make its tables, each called as a function on the run) and the scaling study.

A step is a verb of this command line applied to the run: ``index`` (tf-global's place index of
every global dataset's map, before the run), ``timing`` (the side-by-side timing pass; with
``--quick`` one scan per stratum and a contended pass kept, marked; otherwise a pass still
contended after its retries stops the study with its one-line error, the run kept), ``verdict``
(the truth-free verdict of its sequences), ``report``, ``robustness``, ``real-note``. Each is the
verb's own function (:data:`STEP_CALLS`), and the log names the command that does the same by
hand (``tfloc report results/x``), so a table made by ``make bench`` is the table a user gets.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Callable
from pathlib import Path

from tfloc.harness.config import RunConfig, Study


def _index(cfg: RunConfig, quick: bool) -> list[tuple[str, Callable[[], int]]]:
    from tfloc.io.scenario import GLOBAL, read_scenario

    from .index import index

    return [(f"index --dataset {d}", lambda d=d: index(Path(d)))
            for d in cfg.datasets if read_scenario(d).mode == GLOBAL]


def _timing(cfg: RunConfig, quick: bool) -> list[tuple[str, Callable[[], int]]]:
    from .timing import time_run

    if quick:
        return [(f"timing {cfg.out} --per-stratum 1 --allow-contended",
                 lambda: time_run(cfg.out, per_stratum=1, allow_contended=True))]
    return [(f"timing {cfg.out}", lambda: time_run(cfg.out))]


def _verb(step: str, function: str) -> Callable[[RunConfig, bool], list[tuple[str, Callable[[], int]]]]:
    """Step ``step``: the verb module's ``function`` on the run directory (imported when called)."""
    module = f"{__package__}.{step.replace('-', '_')}"
    return lambda cfg, quick: [(f"{step} {cfg.out}",
                                lambda: getattr(importlib.import_module(module), function)(Path(cfg.out)))]


#: step → the calls it makes on a run (each with the command line that does the same by hand)
STEP_CALLS: dict[str, Callable[[RunConfig, bool], list[tuple[str, Callable[[], int]]]]] = {
    "index": _index, "timing": _timing, "verdict": _verb("verdict", "judge"), "report": _verb("report", "report"),
    "robustness": _verb("robustness", "robustness"), "real-note": _verb("real-note", "note")}


def run_steps(cfg: RunConfig, steps: list[str], quick: bool = False) -> None:
    """Run ``steps`` of the run ``cfg`` in order (a failing step raises its one-line error)."""
    for step in steps:
        for command, call in STEP_CALLS[step](cfg, quick):
            print(f"tfloc {command}", file=sys.stderr)
            code = int(call() or 0)
            if code:
                print(f"tfloc {command}: exit {code}", file=sys.stderr)


def run_scaling_study(study: Study, args: argparse.Namespace) -> int:
    """The scaling study a study file of ``kind = "scaling"`` declares (its ``[scaling]`` table:
    the study configuration's fields, and ``quick``), then its figure and README."""
    from .scaling import run_config

    table = dict(study.scaling)
    quick = bool(table.pop("quick", False)) or args.quick
    out = args.out or study.out
    return run_config(table, quick, Path(out), regenerate=args.regenerate, progress=args.progress,
                      command=f"tfloc bench {study.path}")
