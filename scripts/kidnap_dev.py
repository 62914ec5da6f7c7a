"""Choosing tf-plus-recover's recovery rule on the development sequence seq-kidnap-dev
(docs/kidnap.md); the evaluation sequences seq-kidnap-a/b/c are not read.

``scores``: tf-plus tracked along the sequence without recovery; tf-plus's own score at its answer
per scan, split by whether the answer was correct (≤ 10 cm, 2°) or lost (> 0.5 m or 10°): the
truth is read here, offline, to choose the threshold, never by the tracker.
``rule k=v ...``: tf-plus-recover with the given rule values; per event scans to relocalize, false
relocalizations, tracked share, CPU ms per scan (median, and the scans that called tf-global).

Usage: OMP_NUM_THREADS=1 NUMBA_NUM_THREADS=1 .venv/bin/python scripts/kidnap_dev.py scores|rule [k=v ...]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from tfloc.core.matcher import get_matcher
from tfloc.evaluation.kidnap import score_kidnaps
from tfloc.evaluation.trajectory import LOST_DIST_M, LOST_ORIENT_DEG, errors, score_rows
from tfloc.harness.threads import limit_threads
from tfloc.harness.track import track
from tfloc.io.scenario import read_scans, read_scenario

ROOT = Path(__file__).resolve().parents[1]
DEV = ROOT / "data" / "scenarios" / "seq-kidnap-dev"


def _poses(df: pd.DataFrame, p: str) -> np.ndarray:
    return df[[f"{p}_x", f"{p}_y", f"{p}_theta"]].to_numpy(float)


def main(argv: list[str]) -> None:
    limit_threads(1)
    what = argv[0]
    kv = {k: json.loads(v) for k, _, v in (a.partition("=") for a in argv[1:])}
    sc = read_scenario(DEV)
    scans = read_scans(sc)
    big = {"lost_score": 1e9, "accept_score": 1e9} if what == "scores" else {}
    tracker = get_matcher("tf-plus-recover", **{**big, **kv})
    df = pd.DataFrame(track(sc, scans, tracker))
    info = df["info"].map(json.loads)
    score = info.map(lambda i: i.get("score", np.nan)).to_numpy(float)
    d, o = errors(_poses(df, "est"), _poses(df, "true"))
    ok = (d <= 0.10) & (np.degrees(o) <= 2.0)
    lost = (d > LOST_DIST_M) | (np.degrees(o) > LOST_ORIENT_DEG)
    ids = list(df["scan_id"])
    events = [ids.index(k) for k in sc.extra["kidnaps"]]
    ks = score_kidnaps(_poses(df, "est"), _poses(df, "true"), _poses(df, "init"), events)
    cpu = df["cpu_s"].to_numpy(float) * 1e3
    called = info.map(lambda i: bool(i.get("lost"))).to_numpy(bool)
    q = [50, 90, 95, 99, 100]
    out = {"what": what, **kv, "scans": len(df), "tracked": round(float(ok.mean()), 4),
           "score_correct_pct": dict(zip(map(str, q), np.round(np.percentile(score[ok], q), 4).tolist(), strict=True)),
           "score_lost_pct": (dict(zip(map(str, [0, 1, 5, 10, 50]), np.round(np.percentile(score[lost], [0, 1, 5, 10, 50]), 4).tolist(), strict=True))
                              if lost.any() else None),
           "events": list(ks.events), "scans_to_relocalize": list(ks.scans_to_relocalize),
           "false_relocalizations": list(ks.false_relocalizations),
           "global_calls": int(called.sum()), "relocalized": int(info.map(lambda i: bool(i.get("relocalized"))).sum()),
           "cpu_ms_median": round(float(np.median(cpu)), 2),
           "cpu_ms_median_global_calls": round(float(np.median(cpu[called])), 1) if called.any() else None,
           "losses": score_rows(df).losses}
    print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
