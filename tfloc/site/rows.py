"""A run directory's headline rows, as the site reads them: its ``headline.csv`` through the
store (computed once, by the derive step of ``tfloc report``: :mod:`tfloc.harness.derive`); a
run without one shows "no headline yet". Each dataset's kind (real or simulated) comes with the
rows, read from its ``scenario.json`` (:mod:`tfloc.site.runs`). Percentages in %, errors in cm,
CPU in ms."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from tfloc.core.rows.headline import POOLED, HeadlineRow
from tfloc.errors import TflocError
from tfloc.io.rundir import RunDir
from tfloc.io.tables import HEADLINE

from .runs import dataset_kinds, run_info


@dataclass(frozen=True)
class RunRows:
    """The headline rows of one run directory (``exists``: the directory is there; ``reported``:
    it has a ``headline.csv``; ``kinds``: dataset → ``real`` or ``simulated``, for the datasets
    whose ``scenario.json`` could be read)."""

    name: str
    path: Path
    exists: bool
    reported: bool = False
    rows: list[HeadlineRow] = field(default_factory=list)
    kinds: dict[str, str] = field(default_factory=dict)


def run_rows(root: Path, name: str) -> RunRows:
    """The headline rows of ``root/name`` (none where it has no ``headline.csv``; a malformed
    one is a one-line :class:`~tfloc.errors.ResultsError`)."""
    path = Path(root) / name
    rd = RunDir(path)
    if not path.is_dir():
        return RunRows(name, path, False)
    if not rd.has(HEADLINE):
        return RunRows(name, path, True)
    rows = rd.read(HEADLINE)
    try:
        info = run_info(path)
    except TflocError:
        info = None
    kinds = dataset_kinds(info, [r.scope for r in rows if r.scope != POOLED], Path(root).resolve().parent) \
        if info is not None else {}
    return RunRows(name, path, True, True, rows, kinds)
