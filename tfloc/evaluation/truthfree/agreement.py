"""The verdict checked against the truth, on recordings that have one: does the truth-free
ranking of the trackers agree with the truth-based one, and which scans does it judge wrongly?

Per recording: Spearman's rank correlation between the trackers' verdicts (over every scan, as
a robot owner gets them) and their tracked shares (over the scans with truth); the top tracker of
each; whether the verdict's top is the truth's or one the paired test ties with it (exact
McNemar on the scans with truth, α = 0.05); and, over the scans with truth, the beliefs that
are wrong: *missed losses* (believed tracked, not tracked) and *false alarms* (believed lost,
tracked). It *agrees* where ρ ≥ :data:`MIN_RHO` and the top is the same or tied.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import spearmanr

from tfloc.core.rows.verdict import Agreement, TrackerCheck
from tfloc.evaluation.paired import ALPHA
from tfloc.evaluation.stats import mcnemar_exact

#: the rank correlation a verdict must reach to agree with the truth (issue's criterion)
MIN_RHO = 0.8


def tracker_checks(dataset: str, matchers: list[str], scores: list[float], believed: np.ndarray,
                   tracked: np.ndarray, has_truth: np.ndarray) -> list[TrackerCheck]:
    """Per tracker: its verdict, its tracked share and its wrong beliefs on the scans with truth
    (``believed``, ``tracked`` ``(M, N)``; ``has_truth`` ``(N,)``)."""
    out = []
    for i, m in enumerate(matchers):
        b, t = believed[i][has_truth], tracked[i][has_truth]
        n = int(has_truth.sum())
        out.append(TrackerCheck(dataset, m, scores[i], 100 * float(t.mean()) if n else math.nan, n,
                                int((b != t).sum()), int((b & ~t).sum()), int((~b & t).sum())))
    return out


def _top(values: list[float], names: list[str]) -> int:
    return int(np.argmax(np.nan_to_num(np.asarray(values, dtype=float), nan=-np.inf)))


def agreement(dataset: str, checks: list[TrackerCheck], tracked: np.ndarray,
              has_truth: np.ndarray) -> Agreement:
    """The :class:`Agreement` of one recording from its trackers' checks (in the order of
    ``tracked``'s rows)."""
    names = [c.matcher for c in checks]
    score = [c.score_pct for c in checks]
    truth = [c.truth_pct for c in checks]
    ok = np.isfinite(score) & np.isfinite(truth)
    rho = math.nan
    if ok.sum() >= 3 and np.ptp(np.asarray(score)[ok]) > 0 and np.ptp(np.asarray(truth)[ok]) > 0:
        rho = float(spearmanr(np.asarray(score)[ok], np.asarray(truth)[ok]).statistic)
    it, iv = _top(truth, names), _top(score, names)
    a, b = tracked[it][has_truth], tracked[iv][has_truth]
    p = 1.0 if it == iv else mcnemar_exact(int((a & ~b).sum()), int((~a & b).sum()))
    top = "same" if it == iv else "tied" if p >= ALPHA else "different"
    n = sum(c.truth_scans for c in checks)
    wrong = sum(c.wrong for c in checks)
    return Agreement(dataset, len(checks), rho, names[it], names[iv], top, p,
                     100 * wrong / n if n else math.nan, sum(c.missed_losses for c in checks),
                     sum(c.false_alarms for c in checks),
                     bool(np.isfinite(rho) and rho >= MIN_RHO and top != "different"))
