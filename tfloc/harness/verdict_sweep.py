"""``tfloc verdict RUN --sweep KEY=V1,V2``: the truth-free verdict under other values of its rules,
each checked against the truth where the run has one (``verdict_sweep.csv``).

How the verdict's values were chosen on the development split, and how another choice would
have fared on the held-out recordings: one row per (configuration, recording with truth), the
agreement figures of :mod:`tfloc.evaluation.truthfree.agreement`. The restarts are left out
(they are reported beside the verdict, never counted in it).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, fields, replace
from pathlib import Path

import pandas as pd

from tfloc.core.rows.verdict import SweepRow
from tfloc.errors import ConfigError
from tfloc.evaluation.truthfree.config import TruthFreeConfig
from tfloc.io.rundir import RunDir
from tfloc.io.tables import VERDICT_SWEEP

from .verdict import DEFAULT, judge_run


def parse_sweep(items: list[str], base: TruthFreeConfig = DEFAULT) -> list[tuple[str, TruthFreeConfig]]:
    """``["fit_margin=0.05,0.2", …]`` → the configurations to judge with, each named by what it
    changes (``default`` first); one value changed at a time. A bad key or value: one line."""
    kinds = {f.name: type(getattr(base, f.name)) for f in fields(base)}
    out = [("default", base)]
    for item in items:
        key, sep, values = item.partition("=")
        key = key.strip()
        if not sep or key not in kinds:
            raise ConfigError(f"--sweep {item!r}: give KEY=V1,V2 with KEY one of {', '.join(kinds)}")
        for v in values.split(","):
            try:
                value = kinds[key](float(v)) if kinds[key] is not str else v
            except ValueError:
                raise ConfigError(f"--sweep {key}: {v!r} is not a number") from None
            try:
                out.append((f"{key}={v.strip()}", replace(base, **{key: value})))
            except (TypeError, ValueError) as exc:
                raise ConfigError(f"--sweep {key}={v}: {exc}") from None
    return out


def sweep(run_dir: str | Path, configs: list[tuple[str, TruthFreeConfig]],
          log: Callable[[str], None] = print) -> pd.DataFrame:
    """Every configuration's agreement with the truth per recording (module notes); written to
    ``RUN/verdict_sweep.csv``."""
    rows = []
    for name, cfg in configs:
        v = judge_run(run_dir, cfg, restarts=False, log=lambda _m: None)
        for a in v.agreements:
            rows.append(SweepRow(config=name, **asdict(a)))
        agree = sum(a.agrees for a in v.agreements)
        rhos = [a.rho for a in v.agreements if not math.isnan(a.rho)]
        log(f"{name}: agrees on {agree} of {len(v.agreements)} recordings; "
            f"rho min {min(rhos):.2f}" if rhos else f"{name}: no recording with truth")
    rd = RunDir(Path(run_dir))
    rd.write(VERDICT_SWEEP, rows)
    return rd.frame(VERDICT_SWEEP)
