"""Test-only oracles of ``tf-plus``: the staged, step-by-step path its compiled calls replace,
the grid scores on their own, and the heading seeds from two turning functions (directly, and
by FFTs as they were computed before the direct sum)."""

from __future__ import annotations

import numpy as np
import pytest

from tfloc.paper.turning import TurningFunction
from tfloc.tfplus import pipeline
from tfloc.tfplus import refine as refine_module
from tfloc.tfplus.coarse_kernel import grid_scores_kernel
from tfloc.tfplus.headings import (
    _correlation,
    _kernel_spectrum,
    _pair_kernel,
    _peaks,
    _raw_histograms,
)
from tfloc.tfplus.view import MapView


def step_by_step_tfplus(monkeypatch: pytest.MonkeyPatch) -> None:
    """Run ``tf-plus`` the step-by-step way for the rest of the test (or the
    ``monkeypatch.context()``): no one-call pipeline, and the refinement against virtual scans
    iteration by iteration from Python on vector maps too."""
    monkeypatch.setattr(pipeline, "plan_for", lambda *args, **kwargs: None)
    monkeypatch.setattr(refine_module, "_refine_vector", refine_module._refine_steps)


def grid_scores(field: MapView, points: np.ndarray, positions: np.ndarray,
                headings: np.ndarray) -> np.ndarray:
    """Mean distance-field value ``(N, H)`` of ``points`` ``(M, 2)`` at every position ×
    heading."""
    return grid_scores_kernel(field.table, float(field.origin[0]), float(field.origin[1]),
                              field.resolution, np.ascontiguousarray(points, dtype=float),
                              np.ascontiguousarray(positions, dtype=float),
                              np.ascontiguousarray(headings, dtype=float))


def rotation_candidates(real: TurningFunction, virtual: TurningFunction, max_rotation: float,
                        count: int = 2, bins: int = 720, smoothing: float = np.radians(1.0),
                        skip_closure: bool = True) -> np.ndarray:
    """Up to ``count`` rotation offsets (radians, real = virtual rotated by it), best first:
    the highest local maxima of the histograms' circular cross-correlation within
    ±max_rotation, from two turning functions (what
    :func:`~tfloc.tfplus.headings.scan_rotations` computes from two scans)."""
    raw = _raw_histograms(real.breaks, real.angles, virtual.breaks, virtual.angles, bins,
                          skip_closure)
    width = 2 * np.pi / bins
    k = int(np.floor(max_rotation / width))
    c = _correlation(raw, _pair_kernel(bins, float(smoothing)), k)
    return (_peaks(c, count) - k) * width


def rotation_candidates_fft(real: TurningFunction, virtual: TurningFunction, max_rotation: float,
                            count: int = 2, bins: int = 720, smoothing: float = np.radians(1.0),
                            skip_closure: bool = True) -> np.ndarray:
    """:func:`rotation_candidates` by FFTs of the smoothed histograms, as the seeds were
    computed before the direct sum (rounding-noise maxima count as peaks here)."""
    # edge_histogram of both at once: the raw histograms compiled, the two rows' FFTs in one call
    raw = _raw_histograms(real.breaks, real.angles, virtual.breaks, virtual.angles, bins,
                          skip_closure)
    smooth = np.real(np.fft.ifft(np.fft.fft(raw) * _kernel_spectrum(bins, float(smoothing))))
    spectrum_r, spectrum_v = np.fft.fft(smooth)
    corr = np.real(np.fft.ifft(spectrum_r * np.conj(spectrum_v)))   # corr[k]: hv shifted by k
    width = 2 * np.pi / bins
    k = int(np.floor(max_rotation / width))
    shifts = np.arange(-k, k + 1)
    c = corr[shifts % bins]
    peak = (c >= np.roll(c, 1)) & (c >= np.roll(c, -1))
    peak[0] = peak[-1] = False
    order = np.argsort(-np.where(peak, c, -np.inf))[:count]
    order = order[peak[order]]
    if len(order) == 0:
        order = np.array([int(np.argmax(c))])
    return shifts[order] * width
