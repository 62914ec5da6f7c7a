"""Synthetic ``estimates.csv`` rows and run directories for the metrics and report tests."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from tfloc.io.estimates import COLUMNS


def row(matcher: str = "A", dist_m: float | None = 0.01, orient_deg: float | None = 0.5,
        init_dist_m: float = 0.5, init_deg: float = 5.0, status: str = "ok",
        runtime_s: float | None = 0.01, dataset: str = "detail-1", scan_id: str = "s0",
        group: str = "g", truth: bool = True, score_est: float | None = None,
        score_true: float | None = None, outcome: str = "", cpu_s: float | None = None) -> dict:
    """One result row. The true pose is at the origin facing 0; the initial pose lies along +x
    at ``init_dist_m`` with heading ``init_deg``; the estimate along +y at ``dist_m`` with
    heading ``orient_deg`` (``None``: no estimate)."""
    r = {c: np.nan for c in COLUMNS}
    r.update(dataset=dataset, scan_id=scan_id, group=group, matcher=matcher, status=status,
             outcome=outcome, info="{}", init_x=init_dist_m, init_y=0.0, init_theta=math.radians(init_deg))
    if truth:
        r.update(true_x=0.0, true_y=0.0, true_theta=0.0, init_dist_err_m=init_dist_m,
                 init_orient_err_rad=math.radians(init_deg))
    if dist_m is not None:
        r.update(est_x=0.0, est_y=dist_m, est_theta=math.radians(orient_deg))
        if truth:
            r.update(dist_err_m=dist_m, orient_err_rad=math.radians(orient_deg))
    if runtime_s is not None:
        r.update(runtime_s=runtime_s, converged=1, iterations=10, evaluations=20)
        r.update(cpu_s=runtime_s if cpu_s is None else cpu_s)
    r.update(score_est=score_est, score_true=score_true)
    return r


def frame(rows: list[dict]) -> pd.DataFrame:
    return pd.DataFrame(rows, columns=COLUMNS)


def synthetic_run(path: Path, truth: bool = True, seed: int = 7, wall_per_cpu: float = 2.0) -> Path:
    """A run directory with estimates for the paper's datasets and one scan-to-scan dataset
    (wall time ``wall_per_cpu`` × CPU time)."""
    rng = np.random.default_rng(seed)
    rows = []
    datasets = ["detail-1", "detail-2", "detail-3", "office-pool", "real-x-relations"]
    for d in datasets:
        for i in range(36):
            init_d = rng.uniform(0.0, 3.0) if d != "real-x-relations" else rng.uniform(0.0, 0.3)
            init_a = rng.uniform(0.0, 15.0)
            for m, scale in (("tf", 0.05), ("csm-corr", 0.005)):
                wall = float(rng.uniform(0.001, 0.5))
                status = "ok"
                if m == "tf" and i == 3:
                    status = "timeout"
                if m == "tf" and i == 5:
                    status = "error:ValueError: synthetic"
                bad = m == "tf" and i % 7 == 0
                dist = float(rng.exponential(scale)) + (1.5 if bad else 0.0)
                ang = float(rng.exponential(scale * 20)) + (20.0 if bad else 0.0)
                ok = status == "ok"
                succ = dist <= 0.10 and ang <= 2.0
                rows.append(row(m, dist if ok else None, ang if ok else None, init_d, init_a, status,
                                wall if ok else None, d, f"{d}-{i:03d}",
                                "local" if i % 2 else "loop", truth,
                                score_est=None if succ or not ok else 1.0,
                                score_true=None if succ or not ok else (0.5 if i % 2 else 2.0),
                                outcome="", cpu_s=wall / wall_per_cpu))
    declared = {d: {"mode": "single", "paper_scenarios": ["I"]} for d in datasets[:3]}
    declared["office-pool"] = {"mode": "single", "paper_scenarios": ["II", "III"]}
    declared["real-x-relations"] = {"mode": "scan-to-scan", "paper_scenarios": []}
    return write_run(path, rows, {d: str(path / "no-such-dir" / d) for d in datasets}, declared)


def write_run(path: Path, rows: list[dict], datasets: dict[str, str], declared: dict | None = None) -> Path:
    """A run directory: ``estimates.csv`` of ``rows`` and a ``run.json`` as the runner writes it
    (matchers tf and csm-corr, thresholds 10 cm / 2°; ``declared``: what each dataset's
    ``scenario.json`` declares, as the runner records it)."""
    path.mkdir(parents=True, exist_ok=True)
    frame(rows).to_csv(path / "estimates.csv", index=False)
    run = {"config": {"name": "synthetic", "matchers": [{"label": "tf", "name": "tf", "params": {}},
                                                        {"label": "csm-corr", "name": "csm-corr", "params": {}}],
                      "jobs": 2, "timeout_s": 10.0, "limit_per_group": 0,
                      "success": {"dist_m": 0.1, "orient_deg": 2.0}},
           "versions": {"tfloc": "0.1.0"}, "git": {"commit": "abc123", "dirty": False},
           "machine": {"platform": "test", "cpu_count": 2, "python": "3.11"},
           "datasets": datasets, "declared": declared or {},
           "sessions": [{"started": "2026-01-01T00:00:00+0000", "tasks": 10, "already_done": 0,
                         "loadavg_start": [3.5, 3.0, 2.5], "loadavg_end": [4.25, 3.5, 3.0]}]}
    (path / "run.json").write_text(json.dumps(run))
    return path


def derive_tracking(run_dir, df, scenarios: dict):
    """The tracking tables the derive step writes (``tracking.csv``, ``kidnap.csv``,
    ``start.csv``) for rows ``df`` of sequence datasets, in the store of ``run_dir``; returns the
    :class:`~tfloc.io.rundir.RunDir` the tracking section draws from."""
    from tfloc.evaluation.sequences import kidnap_events, sequence_scores, start_scores
    from tfloc.io.rundir import RunDir
    from tfloc.io.tables import KIDNAP, START, TRACKING

    rd = RunDir(run_dir)
    extras = {n: sc.extra for n, sc in scenarios.items()}
    for table, rows in ((TRACKING, sequence_scores(df, extras)), (KIDNAP, kidnap_events(df, extras)),
                        (START, start_scores(df, extras))):
        if rows:
            rd.write(table, rows)
    return rd
