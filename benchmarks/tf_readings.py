"""The reading study of ``tf``: run the matchers of a run configuration (``benchmarks/tf-readings.toml``,
a ``[[sweep]]`` over TfConfig's switches) on a development or held-out selection of scans, with
the CPU time of each ``localize`` call (``time.process_time``), in this one process.

Development split: the first ``limit_per_group`` scans of each group (the TOML's 40 per
d{i}-a{j} cell of office-pool = 360 scans). Held-out: ``--skip-per-group 40`` takes the scans
*after* the first 40 of each group (what the harness cannot select), and ``--datasets`` points
at other datasets (detail-1/2/3, the real scan-to-map logs) with ``--limit-per-group 0``.

Rows follow ``estimates.csv`` (metres, radians) with ``runtime_s`` = CPU seconds and
``search_outcome`` (:mod:`tfloc.evaluation.outcome`); the file is appended to and resumed.

Run (from the project root)::

    .venv/bin/python benchmarks/tf_readings.py --out dev.csv                       # development
    .venv/bin/python benchmarks/tf_readings.py --out held.csv --skip-per-group 40 \\
        --matchers tf-literal,tf-best --limit-per-group 0                           # held-out pool
    .venv/bin/python benchmarks/tf_readings.py --summary dev.csv                    # the table
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from tfloc import Problem
from tfloc.core.pose import angdiff
from tfloc.evaluation.metrics import dist_bin
from tfloc.evaluation.outcome import SEARCH_OUTCOMES, search_outcome
from tfloc.harness.config import load_config
from tfloc.harness.task import load_matcher
from tfloc.io.scenario import iter_scans, map_for, read_scenario
from tfloc.report.mdtable import table as md_table

ROOT = Path(__file__).resolve().parents[1]
FIELDS = ["dataset", "scan_id", "group", "matcher", "true_x", "true_y", "true_theta", "init_x",
          "init_y", "init_theta", "est_x", "est_y", "est_theta", "runtime_s", "converged",
          "iterations", "evaluations", "status", "dist_err_m", "orient_err_rad", "init_dist_err_m",
          "init_orient_err_rad", "search_outcome"]


def selection(datasets, limit: int, skip: int):
    """(dataset dir, scenario, scan) of each dataset: per group, scans ``skip+1 … skip+limit``."""
    for d in datasets:
        scenario = read_scenario(d)
        seen: dict[str, int] = {}
        for scan in iter_scans(scenario):
            n = seen[scan.group] = seen.get(scan.group, 0) + 1
            if n > skip and (not limit or n <= skip + limit):
                yield d, scenario, scan


def run(config, out: Path, limit: int, skip: int, labels: set[str] | None) -> None:
    done = set()
    if out.exists():
        done = {(r["dataset"], r["scan_id"], r["matcher"]) for r in csv.DictReader(out.open())}
    specs = [m for m in config.matchers if labels is None or m.label in labels]
    maps: dict = {}
    new = not out.exists()
    with out.open("a", newline="") as fh:
        w = csv.DictWriter(fh, FIELDS)
        if new:
            w.writeheader()
        scans = list(selection(config.datasets, limit, skip))
        t_start, n_done = time.time(), 0
        for _d, scenario, scan in scans:  # scan-major: every configuration sees the same load
            problem = Problem(map_for(scenario, scan, maps), scenario.laser, scan.ranges, scan.initial)
            for spec in specs:
                if (scenario.name, scan.scan_id, spec.label) in done:
                    continue
                matcher = load_matcher(spec.name, spec.params_json)
                t0 = time.process_time()
                est = matcher.localize(problem)
                cpu = time.process_time() - t0
                p, t, i = est.pose, scan.true, scan.initial
                dist, orient = p.distance_to(t), abs(angdiff(p.theta, t.theta))
                init_d, init_o = i.distance_to(t), abs(angdiff(i.theta, t.theta))
                w.writerow({"dataset": scenario.name, "scan_id": scan.scan_id, "group": scan.group,
                            "matcher": spec.label, "true_x": t.x, "true_y": t.y, "true_theta": t.theta,
                            "init_x": i.x, "init_y": i.y, "init_theta": i.theta, "est_x": p.x,
                            "est_y": p.y, "est_theta": p.theta, "runtime_s": cpu,
                            "converged": int(est.converged), "iterations": est.iterations,
                            "evaluations": est.evaluations,
                            "status": "failed" if est.info.get("status") == "no-answer" else "ok",
                            "dist_err_m": dist, "orient_err_rad": orient, "init_dist_err_m": init_d,
                            "init_orient_err_rad": init_o,
                            "search_outcome": search_outcome(dist, orient, init_d, config.success)})
            fh.flush()
            n_done += 1
            if n_done % 20 == 0:
                print(f"{n_done}/{len(scans)} scans, {time.time() - t_start:.0f} s", file=sys.stderr)


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a proportion k/n (percent)."""
    if n == 0:
        return math.nan, math.nan
    p = k / n
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return 100 * (c - h), 100 * (c + h)


def summary(df: pd.DataFrame, success_dist_m: float = 0.10, success_orient_deg: float = 2.0) -> pd.DataFrame:
    """One row per matcher label (in first-seen order): success per distance bin with its 95 %
    Wilson interval, errors (cm, degrees), median CPU ms, search outcomes."""
    df = df.copy()
    df["bin"] = dist_bin(df["init_dist_err_m"])
    df["ok"] = (df.dist_err_m <= success_dist_m) & (np.degrees(df.orient_err_rad) <= success_orient_deg)
    rows = []
    for label in dict.fromkeys(df.matcher):
        g = df[df.matcher == label]
        r = {"matcher": label, "n": len(g)}
        for b in ("0–100", "100–200", "200–300"):
            gb = g[g.bin == b]
            lo, hi = wilson(int(gb.ok.sum()), len(gb))
            r[f"succ {b}"] = f"{100 * gb.ok.mean():.0f} ({lo:.0f}–{hi:.0f})" if len(gb) else ""
        lo, hi = wilson(int(g.ok.sum()), len(g))
        r["success %"] = round(100 * g.ok.mean(), 1)
        r["succ 95% CI"] = f"{lo:.0f}–{hi:.0f}"
        r["dist mean/med cm"] = f"{100 * g.dist_err_m.mean():.1f} / {100 * g.dist_err_m.median():.1f}"
        od = np.degrees(g.orient_err_rad)
        r["orient mean/med °"] = f"{od.mean():.2f} / {od.median():.2f}"
        r["CPU ms med"] = round(1000 * g.runtime_s.median(), 1)
        counts = g.search_outcome.value_counts()
        r["near/diverged/other"] = "/".join(str(int(counts.get(o, 0))) for o in SEARCH_OUTCOMES[1:])
        rows.append(r)
    return pd.DataFrame(rows)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default=str(ROOT / "benchmarks" / "tf-readings.toml"))
    ap.add_argument("--out", help="CSV to append to (resumed)")
    ap.add_argument("--datasets", help="comma-separated dataset directories (default: the TOML's)")
    ap.add_argument("--matchers", help="comma-separated labels (default: all of the TOML)")
    ap.add_argument("--limit-per-group", type=int, help="default: the TOML's")
    ap.add_argument("--skip-per-group", type=int, default=0, help="skip the first N scans of each group")
    ap.add_argument("--extra", help='JSON list of extra matchers {"label","name","params"}')
    ap.add_argument("--summary", nargs="+", help="print the summary table of these CSVs and exit")
    a = ap.parse_args(argv)
    if a.summary:
        df = pd.concat([pd.read_csv(p) for p in a.summary])
        for ds, g in [("all", df), *df.groupby("dataset")] if df.dataset.nunique() > 1 else [("all", df)]:
            print(f"\n### {ds}\n")
            t = summary(g)
            print(md_table(list(t.columns), t.astype(str).values.tolist()))
        return
    config = load_config(a.config)
    if a.datasets:
        config = config.with_overrides(datasets=tuple(Path(d) for d in a.datasets.split(",")))
    if a.extra:
        from tfloc.harness.config import MatcherSpec
        extra = tuple(MatcherSpec.make(e["name"], e.get("params"), e.get("label"))
                      for e in json.loads(a.extra))
        config = config.with_overrides(matchers=config.matchers + extra)
    limit = config.limit_per_group if a.limit_per_group is None else a.limit_per_group
    labels = set(a.matchers.split(",")) if a.matchers else None
    run(config, Path(a.out), limit, a.skip_per_group, labels)


if __name__ == "__main__":
    main()
