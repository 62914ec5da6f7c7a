"""Self-assessment: a tracker's own confidence read as a lost-detector, scored against the truth.

Every tracker that reports a confidence in its answers' ``info`` (:mod:`tfloc.core.traits`:
AMCL's particle spread, tf-plus-track's residual, ICP's fitness, the correlative matchers'
scores, ...) is asked: at a false-alarm rate a robot can live with, how many of the scans where
it is *not tracked* (outside the tracked thresholds) does its confidence flag? On the scans
with truth, the detector ranks scans by the confidence turned to *lostness*; a scan without a
value (a gated matcher that did not match) keeps the last value reported before it.

* **AUC**: the area under the ROC of lostness against "not tracked" (the Mann–Whitney
  probability that a lost scan looks less sure than a tracked one; ties count half); 0.5 is
  chance. NaN without both kinds of scan.
* **caught at 1 %**: the share of lost scans whose lostness exceeds the 99th percentile of the
  tracked scans' (the threshold that raises a false alarm on 1 % of tracked scans).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
from scipy.stats import rankdata

from tfloc.core.rows.tracking import SelfAssessment
from tfloc.core.traits import Confidence, confidence_of

from .metrics import tracked

#: the false-alarm rate of the "caught" figure
FALSE_ALARM = 0.01


def values(info: pd.Series, conf: Confidence) -> np.ndarray:
    """The confidence of each row (``info`` JSON text, in scan order) as lostness; a row without
    one keeps the last earlier value (NaN before the first)."""
    raw = info.map(lambda t: json.loads(t or "{}").get(conf.key) if isinstance(t, str) else None)
    v = pd.to_numeric(raw, errors="coerce").ffill().to_numpy(float)
    return np.array([conf.lostness(x) for x in v])


def auc(lostness: np.ndarray, lost: np.ndarray) -> float:
    """The ROC AUC of ``lostness`` against ``lost`` (Mann–Whitney, ties half)."""
    n1, n0 = int(lost.sum()), int((~lost).sum())
    if not n1 or not n0:
        return math.nan
    r = rankdata(lostness)
    return float((r[lost].sum() - n1 * (n1 + 1) / 2) / (n1 * n0))


def caught(lostness: np.ndarray, lost: np.ndarray, false_alarm: float = FALSE_ALARM) -> float:
    """The share of lost scans above the ``1 − false_alarm`` quantile of the tracked scans'
    lostness."""
    if not lost.any() or lost.all():
        return math.nan
    threshold = float(np.quantile(lostness[~lost], 1.0 - false_alarm))
    return float(np.mean(lostness[lost] > threshold))


def assess(scope: str, matcher: str, conf: Confidence, lostness: np.ndarray,
           lost: np.ndarray) -> SelfAssessment:
    """The :class:`SelfAssessment` of one tracker on the scans given (lostness NaN: left out)."""
    ok = np.isfinite(lostness)
    x, y = lostness[ok], lost[ok]
    return SelfAssessment(scope, matcher, conf.key, int(ok.sum()), int(y.sum()), auc(x, y), caught(x, y))


POOLED = "all"


def _scan_order(g: pd.DataFrame) -> pd.DataFrame:
    """A tracker's rows of one dataset in scan order (by stamp where there is one)."""
    if "stamp" in g.columns and g["stamp"].notna().all():
        return g.assign(_t=g["stamp"].astype(float)).sort_values("_t", kind="stable")
    return g


def self_assessments(p: pd.DataFrame, sequences: list[str], thr, confidence=None) -> list[SelfAssessment]:
    """Every tracker's lost-detector on each sequence dataset with truth of prepared rows ``p``
    and pooled over them (``all``, one threshold across recordings, as a robot would use it);
    ``confidence``: label → :class:`Confidence` (default :func:`tfloc.core.traits.confidence_of`).
    Trackers without a confidence are left out."""
    conf_of = confidence or confidence_of
    out: list[SelfAssessment] = []
    pooled: dict[str, tuple[Confidence, list[np.ndarray], list[np.ndarray]]] = {}
    for m in dict.fromkeys(p["matcher"]):
        conf = conf_of(m)
        if conf is None or "info" not in p.columns:
            continue
        for d in sequences:
            g = _scan_order(p[(p["matcher"] == m) & (p["dataset"] == d)])
            if not len(g) or not g["truth"].any():
                continue
            x = values(g["info"], conf)
            t = g["truth"].to_numpy(bool)
            lost = ~tracked(g, thr)
            out.append(assess(d, m, conf, x[t], lost[t]))
            c, xs, ls = pooled.setdefault(m, (conf, [], []))
            xs.append(x[t])
            ls.append(lost[t])
    if len({a.scope for a in out}) > 1:
        for m, (c, xs, ls) in pooled.items():
            out.append(assess(POOLED, m, c, np.concatenate(xs), np.concatenate(ls)))
    return out
