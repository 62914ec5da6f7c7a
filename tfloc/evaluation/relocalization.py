"""Metrics of global localization: top-1, top-5, ``ambiguous`` and cost against map area.

Per scan (:func:`scan_result`), with the run's :class:`~tfloc.evaluation.outcome.Thresholds`:

* **top-1**: the answer (``pose``, the first hypothesis) is within the thresholds;
* **top-5**: any of the first :data:`TOP_K` = 5 hypotheses is (what a tracker could disambiguate
  by moving); a matcher that gives no hypotheses is scored on its answer alone;
* **ambiguous**: the answer is wrong and the matcher's own score prefers it to the truth
  (:func:`~tfloc.evaluation.outcome.failure_kind`, the suite's one rule), so no better search
  could have saved it; unknown when either score is missing;
* no answer (status not ``ok``): neither top-1 nor top-5;
* **place rank**: where a matcher records the places it considered before resolving them
  (``info["proposed"]``, best first: ``tf-global``'s index), the rank of the first within
  :data:`PLACE_DIST_M` and :data:`PLACE_ANGLE_DEG` of the truth (the resolver's reach); 0 = none
  was, so the index, not the resolution, missed the scan. Summarised as place recall @1, @5 and
  over all places proposed.

Per (dataset, matcher) (:func:`summarize`): the rates with Wilson 95 % intervals, the ambiguous
and no-answer shares, the median CPU ms per scan and that cost against the map's free area
(:func:`free_area_m2`). The harness records a global matcher's hypotheses in the row's ``info``
JSON as ``"hypotheses": [[x, y, theta], ...]`` (:func:`hypotheses_from_info` reads them back).
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tfloc.core.pose import Pose, angdiff
from tfloc.core.result import kind_of_status
from tfloc.core.rows.relocalization import GlobalSummary
from tfloc.core.thresholds import Thresholds
from tfloc.errors import ResultsError

from .outcome import AMBIGUOUS, failure_kind
from .stats import wilson

TOP_K = 5
HYPOTHESES_KEY = "hypotheses"
PROPOSED_KEY = "proposed"
PLACE_DIST_M, PLACE_ANGLE_DEG = 0.5, 25.0


def hypotheses_info(hypotheses: Sequence[Pose], k: int = TOP_K) -> list[list[float]]:
    """The first ``k`` hypotheses as the JSON value the harness stores under ``info["hypotheses"]``."""
    return [[float(p.x), float(p.y), float(p.theta)] for p in list(hypotheses)[:k]]


def hypotheses_from_info(info: str | Mapping | None, where: str = "info") -> list[Pose]:
    """The hypotheses a row's ``info`` (JSON text or a dict) holds under ``"hypotheses"``, best
    first; ``[]`` when there are none. A malformed value raises :class:`ResultsError` naming ``where``."""
    if info is None or (isinstance(info, str) and not info.strip()):
        return []
    if isinstance(info, str):
        try:
            info = json.loads(info)
        except json.JSONDecodeError as exc:
            raise ResultsError(f"{where}: info is not JSON ({exc.msg})") from None
    if not isinstance(info, Mapping):
        raise ResultsError(f"{where}: info is not a JSON object")
    raw = info.get(HYPOTHESES_KEY)
    if raw is None:
        return []
    if not isinstance(raw, list):
        raise ResultsError(f"{where}: info 'hypotheses' must be a list of [x, y, theta]")
    out = []
    for j, h in enumerate(raw):
        if (not isinstance(h, list) or len(h) != 3
                or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in h)):
            raise ResultsError(f"{where}: info 'hypotheses'[{j}] is not [x, y, theta] (numbers)")
        p = Pose(float(h[0]), float(h[1]), float(h[2]))
        if not p.is_finite():
            raise ResultsError(f"{where}: info 'hypotheses'[{j}] is not finite")
        out.append(p)
    return out


@dataclass(frozen=True)
class ScanResult:
    """One global localization, scored (a scan × a matcher)."""

    dataset: str
    matcher: str
    answered: bool
    top1: bool
    top5: bool
    ambiguous: bool | None  # None: a score is missing, so it cannot be told
    cpu_s: float
    place_rank: int | None = None  # 1-based; 0: not proposed; None: no places recorded


def place_rank(places: Sequence[Sequence[float]] | None, truth: Pose) -> int | None:
    """The 1-based rank of the first of ``places`` (``[x, y, theta]``, best first) within
    :data:`PLACE_DIST_M` and :data:`PLACE_ANGLE_DEG` of ``truth``; 0 if none is, ``None`` if
    there are no places."""
    if not places:
        return None
    p = np.asarray(places, dtype=float).reshape(-1, 3)
    near = (np.hypot(p[:, 0] - truth.x, p[:, 1] - truth.y) <= PLACE_DIST_M) & (
        np.degrees(np.abs(angdiff(p[:, 2], truth.theta))) <= PLACE_ANGLE_DEG)
    hit = np.flatnonzero(near)
    return int(hit[0]) + 1 if hit.size else 0


def _proposed(info: Any) -> list | None:
    """``info["proposed"]`` of a row (JSON text or dict), or None."""
    if isinstance(info, str):
        try:
            info = json.loads(info) if info.strip() else {}
        except json.JSONDecodeError:
            return None
    got = info.get(PROPOSED_KEY) if isinstance(info, Mapping) else None
    ok = isinstance(got, list) and all(isinstance(h, list) and len(h) == 3 for h in got)
    return got if ok else None


def _within(p: Pose, truth: Pose, thresholds: Thresholds) -> bool:
    return bool(thresholds.success(p.distance_to(truth), angdiff(p.theta, truth.theta)))


def scan_result(dataset: str, matcher: str, truth: Pose, answer: Pose | None,
                hypotheses: Sequence[Pose], thresholds: Thresholds, score_est: float = math.nan,
                score_true: float = math.nan, cpu_s: float = math.nan, k: int = TOP_K) -> ScanResult:
    """Score one global localization (see the module notes); ``answer`` None or not finite = no answer."""
    answered = answer is not None and answer.is_finite()
    if not answered:
        return ScanResult(dataset, matcher, False, False, False, None, float(cpu_s))
    top1 = _within(answer, truth, thresholds)
    cands = list(hypotheses)[:k] or [answer]
    top5 = top1 or any(_within(p, truth, thresholds) for p in cands)
    if top1:
        amb: bool | None = False
    elif math.isfinite(score_est) and math.isfinite(score_true):
        amb = failure_kind(score_est, score_true) == AMBIGUOUS
    else:
        amb = None
    return ScanResult(dataset, matcher, True, top1, top5, amb, float(cpu_s))


def _num(row: Mapping, key: str) -> float:
    v = row.get(key)
    if v is None or (isinstance(v, str) and not v.strip()):
        return math.nan
    try:
        return float(v)
    except (TypeError, ValueError):
        raise ResultsError(f"column {key!r} is not a number: {str(v)[:40]!r}") from None


def result_from_row(row: Mapping[str, Any], thresholds: Thresholds, where: str = "row") -> ScanResult | None:
    """Score an ``estimates.csv`` row (strings or numbers, :data:`tfloc.io.estimates.COLUMNS`);
    ``None`` for a row without truth or with an ``invalid:`` status (no problem was posed)."""
    kind = kind_of_status(str(row.get("status", "")))
    truth = Pose(*(_num(row, f"true_{c}") for c in ("x", "y", "theta")))
    if kind == "invalid" or not truth.is_finite():
        return None
    answer = Pose(*(_num(row, f"est_{c}") for c in ("x", "y", "theta"))) if kind == "ok" else None
    r = scan_result(str(row.get("dataset", "")), str(row.get("matcher", "")), truth, answer,
                    hypotheses_from_info(row.get("info"), where), thresholds,
                    _num(row, "score_est"), _num(row, "score_true"), _num(row, "cpu_s"))
    return dataclasses.replace(r, place_rank=place_rank(_proposed(row.get("info")), truth))


def summarize(results: Iterable[ScanResult],
              free_area: Mapping[str, float] | None = None) -> list[GlobalSummary]:
    """One :class:`GlobalSummary` per (dataset, matcher), in order of first appearance;
    ``free_area`` maps a dataset to its map's free area in m² (NaN where absent)."""
    groups: dict[tuple[str, str], list[ScanResult]] = {}
    for r in results:
        groups.setdefault((r.dataset, r.matcher), []).append(r)
    out = []
    for (ds, m), rs in groups.items():
        n = len(rs)
        k1, k5 = sum(r.top1 for r in rs), sum(r.top5 for r in rs)
        cpu = np.array([r.cpu_s for r in rs], dtype=float)
        cpu = cpu[np.isfinite(cpu)]
        med = float(np.median(cpu) * 1e3) if cpu.size else math.nan
        area = float((free_area or {}).get(ds, math.nan))
        ranks = [r.place_rank for r in rs if r.place_rank is not None]
        recall = [sum(0 < k <= top for k in ranks) / len(ranks) if ranks else math.nan
                  for top in (1, TOP_K, 10**9)]
        out.append(GlobalSummary(
            ds, m, n, k1 / n, *wilson(k1, n), k5 / n, *wilson(k5, n),
            sum(bool(r.ambiguous) for r in rs) / n, sum(not r.answered for r in rs) / n, med, area,
            med / area * 100.0 if area > 0 else math.nan, *recall))
    return out


def summarize_rows(rows: Iterable[tuple[int, Mapping[str, Any]]], thresholds: Thresholds,
                   free_area: Mapping[str, float] | None = None, path: str = "rows") -> list[GlobalSummary]:
    """:func:`summarize` of ``estimates.csv`` rows ``(line, row)`` (as
    :func:`tfloc.io.estimates.read_rows` gives them); rows without truth or ``invalid:`` are left
    out; a malformed ``info`` raises :class:`ResultsError` naming ``path:line``."""
    scored = (result_from_row(row, thresholds, f"{path}:{line}") for line, row in rows)
    return summarize((r for r in scored if r is not None), free_area)


def free_area_m2(map_: Any, clearance: float = 0.0, step: float = 0.1) -> float:
    """The free area (m²) of a map (any :class:`~tfloc.core.map.Map`): the share of a ``step``-metre
    lattice over its bounds that ``is_free`` (with ``clearance``), times the bounds' area."""
    x0, y0, x1, y1 = map_.bounds
    xs = np.arange(x0 + 0.5 * step, x1, step)
    ys = np.arange(y0 + 0.5 * step, y1, step)
    if xs.size == 0 or ys.size == 0:
        return 0.0
    gx, gy = np.meshgrid(xs, ys)
    free = map_.is_free(np.column_stack((gx.ravel(), gy.ravel())), clearance)
    return float(np.count_nonzero(free)) * step * step
