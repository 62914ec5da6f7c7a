"""The modes a dataset poses its scans in, each one object: its key (``scenario.json`` ``"mode"``),
the measure its headline ranks by, the error beside it, the title of its table and the site page
it is shown on. Evaluation, report and site read these; nothing else spells a mode's properties.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Mode:
    """One mode: ``key`` as datasets name it, ``measure`` its headline's success measure (a share
    of scans, %), ``error`` the error shown beside it (in ``error_units``), ``title`` its table's
    heading, ``page`` the site page (``tfloc/site/pages.toml`` key) it belongs to."""

    key: str
    measure: str
    error: str
    title: str
    page: str
    error_units: str = "cm"


SINGLE = Mode("single", "success", "median error", "A single scan from a rough guess", "single-scan")
SCAN_TO_SCAN = Mode("scan-to-scan", "success", "median error", "Scan to scan", "single-scan")
SEQUENCE = Mode("sequence", "tracked", "APE RMSE", "Tracking along a sequence", "tracking")
GLOBAL = Mode("global", "top-1", "median error", "A single scan without a guess (global)", "global")
#: a sequence without truth: ranked by the truth-free verdict (no error: there is no truth)
TRUTH_FREE = Mode("truth-free", "truth-free", "", "Tracking without ground truth: the truth-free verdict",
                  "tracking", "")

#: the modes a dataset may declare, by key, in headline order
MODES: dict[str, Mode] = {m.key: m for m in (SINGLE, SCAN_TO_SCAN, SEQUENCE, GLOBAL)}


def mode_of(key: str) -> Mode:
    """The mode named ``key`` (the truth-free pseudo-mode included); ``single``'s properties for
    an unknown key (older runs that recorded no mode)."""
    if key == TRUTH_FREE.key:
        return TRUTH_FREE
    return MODES.get(key, SINGLE)
