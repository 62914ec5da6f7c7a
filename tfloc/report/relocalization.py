"""The report's section for global datasets (``"mode": "global"``): top-1, top-5, ambiguous,
CPU per scan and cost against the map's free area, per dataset and matcher, from
``relocalization.csv`` (:mod:`tfloc.evaluation.relocalization`, written by the derive step)."""

from __future__ import annotations

import pandas as pd

from tfloc.core.thresholds import Thresholds
from tfloc.evaluation.metrics import status_kinds
from tfloc.io.rundir import RunDir
from tfloc.io.tables import RELOCALIZATION

from .mdtable import num
from .mdtable import table as md_table


def _pct(v: float, lo: float, hi: float) -> str:
    return f"{100 * v:.1f} [{100 * lo:.1f}–{100 * hi:.1f}]"


def relocalization_section(rd: RunDir, df: pd.DataFrame, thresholds: Thresholds) -> str:
    """The markdown of the global section: the run's ``relocalization.csv`` and, from the rows
    ``df`` of its global datasets, the local matchers given no guess."""
    summary = rd.read(RELOCALIZATION)
    invalid = df[status_kinds(df["status"]) == "invalid"].groupby("matcher").size()
    table = md_table(["dataset", "matcher", "n", "top-1 % [95 % CI]", "top-5 % [95 % CI]", "ambiguous %",
                      "no answer %", "CPU ms/scan (median)", "free area m²", "CPU ms per 100 m²"],
                     [[s.dataset, s.matcher, s.n, _pct(s.top1, s.top1_lo, s.top1_hi),
                       _pct(s.top5, s.top5_lo, s.top5_hi), num(100 * s.ambiguous, 1), num(100 * s.no_answer, 1),
                       num(s.cpu_ms_median, 1), num(s.free_area_m2, 0), num(s.ms_per_100m2, 2)] for s in summary])
    text = ["## Global localization (no initial guess)\n",
            "Each scan is localized over the whole map. top-1 = the answer within "
            f"{100 * thresholds.dist_m:g} cm and {thresholds.orient_deg:g}°; top-5 = any of the first five "
            "hypotheses within them (what a robot could tell apart by moving); ambiguous = a wrong answer "
            "the matcher's own score prefers to the truth; CPU per scan with the map's index or grids "
            "built beforehand (their build time is reported apart).\n", table]
    placed = [x for x in summary if x.place_recall_all == x.place_recall_all]  # not NaN
    if placed:
        text.append("\nPlaces the index proposed (where the matcher records them): place recall @k = "
                    "the share of scans with a proposed place within 0.5 m and 25° of the truth among "
                    "its k best (the resolution's reach); what recall misses, the index never offered.\n")
        text.append(md_table(["dataset", "matcher", "place recall @1 %", "@5 %", "all proposed %"],
                             [[x.dataset, x.matcher, num(100 * x.place_recall1, 1), num(100 * x.place_recall5, 1),
                               num(100 * x.place_recall_all, 1)] for x in placed]))
    if len(invalid):
        text.append("Local matchers given these problems got `invalid:` rows (nothing ran): "
                    + ", ".join(f"`{m}` {n}" for m, n in invalid.items()) + ".\n")
    return "\n".join(text)
