"""One-off research helper: a fixed stratified sample of scans for the speed scripts: ``per`` scans of each dataset ×
group (first ``per`` in file order, so "before" and "after" checkouts see the same scans)."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAPER = ("office-pool", "detail-1", "detail-2", "detail-3")
REAL = ("real-intel-scan-to-map",)


def add_sample_args(ap: argparse.ArgumentParser) -> None:
    """The sample's command-line options (``--per``, ``--per-real``, ``--datasets``)."""
    ap.add_argument("--per", type=int, default=4)
    ap.add_argument("--per-real", type=int, default=40)
    ap.add_argument("--datasets", nargs="+", default=list(PAPER + REAL))


def one_core() -> None:
    """Time on one thread (:func:`tfloc.harness.threads.limit_threads`), pinned to the last core
    where the system allows it, so that CPU times are comparable."""
    from tfloc.harness.threads import limit_threads

    limit_threads(1)
    try:
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[-1]})
    except OSError:
        pass


def sample(datasets: tuple[str, ...], per: int, per_real: int) -> list[tuple[str, str, object]]:
    """``(dataset, scan_id, Problem)`` triples: ``per`` scans per group of the paper datasets,
    ``per_real`` scans (evenly spread) of each real dataset."""
    from tfloc.harness.workspace import problem_of
    from tfloc.io.scenario import load_dataset

    out = []
    for name in datasets:
        scenario, scans = load_dataset(str(ROOT / "data" / "scenarios" / name))
        if name.startswith("real-"):
            items = list(scans.values())
            step = max(1, len(items) // per_real)
            chosen = items[::step][:per_real]
        else:
            groups: dict[str, list] = {}
            for s in scans.values():
                groups.setdefault(s.group, []).append(s)
            chosen = [s for g in sorted(groups) for s in groups[g][:per]]
        out += [(name, s.scan_id, problem_of(scenario, s)) for s in chosen]
    return out
