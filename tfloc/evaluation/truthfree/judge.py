"""One recording judged without its truth: every signal per tracker and scan, the beliefs, and
each tracker's line of the verdict (:class:`VerdictRow`).

Inputs are arrays over the run's trackers (M) and the recording's scans (N) in time order:
answers and predictions ``(M, N, 3)`` (metres, radians, map frame), fit shares ``(M, N)`` and
each tracker's method (:func:`tfloc.core.traits.method_of`). Nothing here reads a true pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tfloc.core.rows.verdict import VerdictRow

from . import belief as B
from . import odometry as O
from .config import TruthFreeConfig
from .consensus import consensus
from .score import share


@dataclass(frozen=True, eq=False)
class Judgement:
    """Every per-scan signal of one recording (``(M, N)`` arrays; module notes)."""

    fit: np.ndarray
    best_fit: np.ndarray
    agree: np.ndarray
    known: np.ndarray
    support: np.ndarray
    dist: np.ndarray
    turn: np.ndarray
    odometry_disagrees: np.ndarray
    envelope: tuple[float, float]
    believed: np.ndarray


def judge(est: np.ndarray, init: np.ndarray, fit: np.ndarray, methods: list[str | None],
          cfg: TruthFreeConfig) -> Judgement:
    """The signals and beliefs of one recording (module notes)."""
    agree, known, support = consensus(est, methods, cfg.agree_m, cfg.agree_rad, cfg.min_methods)
    dist, turn = O.corrections(est, init)
    backed = np.where(known, agree, B.fits_best(fit, cfg.fit_margin))
    env = O.envelope(dist, turn, backed, cfg.envelope_quantile, cfg.min_envelope_m, cfg.min_envelope_rad)
    odo = O.disagrees(dist, turn, env, cfg.odometry_factor)
    believed = B.believed(agree, known, fit, odo, cfg.fit_margin)
    return Judgement(fit, B.best_fit(fit), agree, known, support, dist, turn, odo, env, believed)


def _pct(x: np.ndarray) -> float:
    return float(100.0 * np.mean(x)) if np.size(x) else float("nan")


def verdict_rows(dataset: str, matchers: list[str], j: Judgement, cfg: TruthFreeConfig,
                 reconverged: dict[str, np.ndarray] | None = None) -> list[VerdictRow]:
    """Each tracker's :class:`VerdictRow` from a :class:`Judgement` (``reconverged``: per
    tracker, whether each of its restarts returned)."""
    out = []
    for i, m in enumerate(matchers):
        s, lo, hi = share(j.believed[i], cfg.block_scans, cfg.resamples, cfg.seed)
        known = j.known[i]
        back = (reconverged or {}).get(m)
        out.append(VerdictRow(
            dataset, m, 100 * s, 100 * lo, 100 * hi, int(j.believed.shape[1]), _pct(known),
            _pct(j.agree[i][known]), float(100 * np.nanmean(j.fit[i])) if np.isfinite(j.fit[i]).any() else float("nan"),
            _pct(j.odometry_disagrees[i]), int(np.sum(j.dist[i] > cfg.jump_m)),
            _pct(back) if back is not None and back.size else float("nan"),
            int(back.size) if back is not None else 0))
    return out
