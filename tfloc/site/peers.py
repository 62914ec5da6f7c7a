"""A generated block that sets chosen matchers of one run side by side, recording by recording:
``<!-- tfloc:begin peers.RUN.M1.M2... -->`` in a doc (a baseline's page comparing it with its
peers). Each cell is the run's ``headline.csv``: the measure (tracked, success or top-1, %), its
rank among the run's matchers, the error (cm) and the median CPU per scan (ms)."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from tfloc.core.rows.headline import POOLED
from tfloc.io.rundir import RunDir
from tfloc.io.tables import HEADLINE
from tfloc.report.mdtable import table

PREFIX = "peers."


def is_peers(name: str) -> bool:
    return name.startswith(PREFIX)


def _cell(r: pd.Series | None, n: int) -> str:
    if r is None:
        return "—"
    err = "" if pd.isna(r["error_cm"]) else f" · {float(r['error_cm']):.1f} cm"
    cpu = "" if pd.isna(r["cpu_ms"]) or not math.isfinite(float(r["cpu_ms"])) else f" · {float(r['cpu_ms']):.2g} ms"
    return f"{float(r['value_pct']):.1f} % (#{int(r['rank'])} of {n}){err}{cpu}"


def peers_markdown(name: str, root: Path) -> str:
    """Block ``peers.RUN.M1.M2...`` from ``root/RUN/headline.csv`` (module notes)."""
    run, *matchers = name.removeprefix(PREFIX).split(".")
    rd = RunDir(root / run)
    path = rd.file(HEADLINE)
    if not path.is_file() or not matchers:
        return f"_Not yet: no {path.relative_to(root.parent) if root.parent in path.parents else path}._\n"
    df = rd.frame(HEADLINE)
    df = df[df["mode"] == df["mode"].iloc[0]] if len(df) else df   # the run's first mode
    scopes = list(dict.fromkeys(df["scope"]))
    body = []
    for scope in scopes:
        s = df[df["scope"] == scope]
        n = s["matcher"].nunique()
        rows = {r["matcher"]: r for _, r in s.iterrows()}
        body.append(["pooled" if scope == POOLED else scope] + [_cell(rows.get(m), n) for m in matchers])
    measure = str(df["measure"].iloc[0]) if len(df) else "measure"
    note = (f"`results/{run}/headline.csv`: {measure} (%, rank among the run's matchers) · "
            f"{df['error'].iloc[0] if len(df) else 'error'} · median CPU per scan.\n")
    return table(["recording", *(f"`{m}`" for m in matchers)], body, "l" + "r" * len(matchers)) + "\n" + note
