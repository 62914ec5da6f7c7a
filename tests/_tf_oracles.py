"""Test-only oracles of the paper's method (``tf``): the step-by-step path its compiled calls
replace, the L1 match as a ``Match``, and the ShortStraw pieces the package runs only inside its
compiled ShortStraw."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from tfloc.core.pose import wrap_angle
from tfloc.paper import matcher as paper_matcher
from tfloc.paper.corners import _merge_lines_into, _walk
from tfloc.paper.shape import scan_turning_function
from tfloc.paper.turning import Match, TurningFunction, _best_shift, match


class StepByStepCost(paper_matcher._Cost):
    """``tf``'s cost evaluations without the compiled paths: no compiled Function1 or search
    (the Python simplex runs), and each virtual scan's Err from its turning function built and
    matched step by step (``match`` of this module, so that a test can swap it)."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self._vector = None

    def _scan_errors(self, scans: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        cfg, laser = self.config, self.problem.laser
        errs, rots = np.full(len(scans), cfg.penalty), np.zeros(len(scans))
        distance = match_l1 if cfg.err_norm == "l1" else match
        for j, ranges in enumerate(scans):
            tf_v = scan_turning_function(ranges, laser, cfg.shape)
            if tf_v is not None:
                m = distance(self.real, tf_v)
                errs[j], rots[j] = m.distance, m.rotation
        return errs, rots


def step_by_step_tf(monkeypatch: pytest.MonkeyPatch) -> None:
    """Run ``tf`` (and ``tf-best``) the step-by-step way for the rest of the test (or the
    ``monkeypatch.context()``): :class:`StepByStepCost` for the matcher's cost."""
    monkeypatch.setattr(paper_matcher, "_Cost", StepByStepCost)


@njit(cache=True, nogil=True)
def resample_path(points: np.ndarray, spacing: float) -> np.ndarray:
    """Algorithm 1 along the path (Wolin et al.'s RESAMPLE-POINTS, ``(M, 2)``): the walk
    ``shortstraw(..., along_path=True)`` takes."""
    return _walk(points, spacing, True)


def straws(points: np.ndarray, window: int = 1) -> np.ndarray:
    """Eq. 7 / Alg. 2: squared straw ``‖p(i−w) − p(i+w)‖²`` for ``i = w … N−w−1`` (metres²)."""
    d = points[2 * window:] - points[:-2 * window]
    return np.einsum("ij,ij->i", d, d)


@njit(cache=True, nogil=True)
def merge_lines(points: np.ndarray, corners: np.ndarray,
                threshold: float = 0.95) -> np.ndarray:
    """Algorithm 3 on consecutive corner triples (the package's
    :func:`~tfloc.paper.corners._merge_lines_into` with buffers of its own): the corners kept."""
    k = corners.shape[0]
    if k < 3:
        return corners.astype(np.int64)
    keep = np.empty(k, dtype=np.int64)
    m = _merge_lines_into(points, corners, threshold, np.empty(points.shape[0]), keep)
    return keep[:m].copy()


def is_line(points: np.ndarray, a: int, b: int, threshold: float = 0.95) -> bool:
    """Algorithm 3 (Is-Line): whether the resampled path ``points[a..b]`` is straight."""
    path = np.sum(np.hypot(*np.diff(points[a:b + 1], axis=0).T))
    return bool(path > 0 and np.hypot(*(points[b] - points[a])) / path > threshold)


@njit(cache=True, nogil=True)
def _match_l1(rb: np.ndarray, ra: np.ndarray, vb: np.ndarray,
              va: np.ndarray) -> tuple[float, float, int]:
    """(area, rot, shift) of Sec. 4.3's area between the graphs
    (:func:`~tfloc.paper.turning._best_shift` with ``l1``)."""
    return _best_shift(rb, ra, vb, va, True)


def match_l1(real: TurningFunction, virtual: TurningFunction) -> Match:
    """Sec. 4.3's area between the graphs as a :class:`~tfloc.paper.turning.Match`, like
    :func:`~tfloc.paper.turning.match` for Eq. 13: ``distance`` is the area (radians × unit arc
    length), minimised over starting vertex and rotation."""
    area, rot, k = _match_l1(real.breaks, real.angles, virtual.breaks, virtual.angles)
    return Match(float(area), wrap_angle(float(rot)), int(k))
