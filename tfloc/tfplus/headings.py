"""Heading error from turning functions, without a position: edge-direction histograms.

A turning function's value Θ(s) is the direction (radians, sensor frame) of the polygon edge at
arc length s, whatever vertex the polygon starts at. Binning Θ mod 2π weighted by edge length
gives an edge-direction histogram of the scan; rotating the robot shifts it circularly, and
moving the robot mostly changes how long each wall looks, not its direction. The circular
cross-correlation of the real and the virtual scan's histograms, searched over ±``max_rotation``
(the initial guess's heading is that good), peaks at the rotation offset. The two closing edges
through the sensor origin (:func:`tfloc.paper.shape.scan_polygon`) are not walls and are left out.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numba import njit

from tfloc.paper.kernels import scan_turning
from tfloc.paper.turning import TurningFunction


def edge_histogram(tf: TurningFunction, bins: int, smoothing: float, skip_closure: bool) -> np.ndarray:
    """Length-weighted histogram ``(bins,)`` of edge directions over [0, 2π), smoothed by a
    circular Gaussian of ``smoothing`` radians."""
    lengths = np.diff(tf.breaks)
    angles = np.mod(tf.angles, 2 * np.pi)
    if skip_closure and len(angles) > 3:
        lengths, angles = lengths[1:-1], angles[1:-1]
    width = 2 * np.pi / bins
    raw = np.bincount(np.minimum((angles / width).astype(np.int64), bins - 1), lengths, bins)
    return np.real(np.fft.ifft(np.fft.fft(raw) * _kernel_spectrum(bins, float(smoothing))))


@njit(cache=True, nogil=True)
def _raw_histograms(real_breaks: np.ndarray, real_angles: np.ndarray, virtual_breaks: np.ndarray,
                    virtual_angles: np.ndarray, bins: int, skip_closure: bool) -> np.ndarray:
    """:func:`edge_histogram`'s histograms before smoothing, of the real (row 0) and the virtual
    (row 1) turning function, ``(2, bins)``: the same values as its numpy steps (Python's float
    ``%`` is ``np.mod``; weights added in edge order as ``np.bincount`` adds them)."""
    out = np.zeros((2, bins))
    width = 2 * np.pi / bins
    for row in range(2):
        breaks = real_breaks if row == 0 else virtual_breaks
        angles = real_angles if row == 0 else virtual_angles
        n = angles.shape[0]
        lo, hi = (1, n - 1) if skip_closure and n > 3 else (0, n)
        for i in range(lo, hi):
            b = min(np.int64((angles[i] % (2 * np.pi)) / width), bins - 1)
            out[row, b] += breaks[i + 1] - breaks[i]
    return out


@lru_cache(maxsize=8)
def _kernel_spectrum(bins: int, smoothing: float) -> np.ndarray:
    """FFT of the circular Gaussian (``smoothing`` radians) over ``bins`` bins (read-only; it
    depends on the parameters only, so it is made once)."""
    width = 2 * np.pi / bins
    d = (np.arange(bins) + bins // 2) % bins - bins // 2            # circular bin offsets
    spectrum = np.fft.fft(np.exp(-0.5 * (d * width / smoothing) ** 2))
    spectrum.setflags(write=False)
    return spectrum


_REACH = 64  # bins: the smoothed histograms' correlation kernel is taken as 0 beyond this
_NOISE = 1e-9  # a local maximum below this fraction of the largest correlation is no peak


@lru_cache(maxsize=8)
def _pair_kernel(bins: int, smoothing: float) -> np.ndarray:
    """``G₂[d + _REACH]`` for ``|d| ≤ _REACH``: the circular autocorrelation of the Gaussian of
    ``smoothing`` radians over ``bins`` bins (read-only). The correlation of two histograms each
    smoothed by that Gaussian is the correlation of the raw ones smoothed by ``G₂``, a Gaussian of
    √2 times the width: beyond ``_REACH`` bins it is below 1e-100 of its peak at 1° smoothing."""
    width = 2 * np.pi / bins
    d = (np.arange(bins) + bins // 2) % bins - bins // 2
    g = np.exp(-0.5 * (d * width / smoothing) ** 2)
    lags = np.arange(-_REACH, _REACH + 1)
    out = np.array([np.dot(np.roll(g, -k), g) for k in lags])
    out.setflags(write=False)
    return out


@njit(cache=True, nogil=True)
def _correlation(raw: np.ndarray, g2: np.ndarray, k_max: int) -> np.ndarray:
    """``c[s + k_max]`` for ``|s| ≤ k_max``: the circular cross-correlation of the smoothed
    histograms of ``raw`` ``(2, bins)`` (row 0 real, row 1 virtual) at shift ``s``,
    ``Σₙ h_real[n + s] · h_virtual[n]``, summed over pairs of occupied raw bins with ``G₂``.

    Summed directly rather than by FFTs: the same values within rounding, but where fewer real
    peaks lie in the window than are asked for, the FFTs' rounding noise (~1e-17 of the peaks)
    makes local maxima of its own, which :func:`_peaks` would take as seeds (``docs/speed.md``)."""
    bins = raw.shape[1]
    reach = (g2.shape[0] - 1) // 2
    real = np.flatnonzero(raw[0])
    virtual = np.flatnonzero(raw[1])
    c = np.zeros(2 * k_max + 1)
    for a in real:
        for b in virtual:
            d0 = (a - b) % bins
            if d0 > bins // 2:
                d0 -= bins
            lo, hi = max(-k_max, d0 - reach), min(k_max, d0 + reach)
            if lo > hi:
                continue
            wgt = raw[0, a] * raw[1, b]
            for s in range(lo, hi + 1):
                c[s + k_max] += wgt * g2[s - d0 + reach]
    return c


@njit(cache=True, nogil=True)
def _peaks(c: np.ndarray, count: int) -> np.ndarray:
    """Indices of up to ``count`` interior local maxima of ``c`` (≥ both neighbours and above
    ``_NOISE`` of the largest value), highest first (ties by index); the first maximum of ``c``
    if there is none."""
    top = c.max()
    keep = np.zeros(c.shape[0], dtype=np.bool_)
    for i in range(1, c.shape[0] - 1):
        keep[i] = c[i] >= c[i - 1] and c[i] >= c[i + 1] and c[i] > _NOISE * top and c[i] > 0.0
    idx = np.flatnonzero(keep)
    if idx.shape[0] == 0:
        return np.array([np.argmax(c)])
    return idx[np.argsort(-c[idx], kind="mergesort")][:count]


@njit(cache=True, nogil=True)
def _scan_rotations(real_ranges: np.ndarray, virtual_ranges: np.ndarray, directions: np.ndarray,
                    max_range: float, spacing: float, window: int, t: float, line_threshold: float,
                    close_through_origin: bool, along_path: bool, bins: int, skip_closure: bool,
                    g2: np.ndarray, k_max: int, count: int) -> tuple[np.ndarray, bool]:
    """:func:`scan_rotations` in one call: both turning functions
    (:func:`tfloc.paper.kernels.scan_turning`), their histograms and correlation, the peaks;
    ``False`` (and no rotations) when either polygon has fewer than 3 edges."""
    rb, ra = scan_turning(real_ranges, directions, max_range, spacing, window, t, line_threshold,
                          close_through_origin, along_path)
    vb, va = scan_turning(virtual_ranges, directions, max_range, spacing, window, t,
                          line_threshold, close_through_origin, along_path)
    if ra.shape[0] < 3 or va.shape[0] < 3:
        return np.empty(0), False
    raw = _raw_histograms(rb, ra, vb, va, bins, skip_closure)
    c = _correlation(raw, g2, k_max)
    return (_peaks(c, count) - k_max) * (2 * np.pi / bins), True


def scan_rotations(real_ranges: np.ndarray, virtual_ranges: np.ndarray, laser, shape,
                   max_rotation: float, count: int, bins: int = 720,
                   smoothing: float = np.radians(1.0), skip_closure: bool = True) -> np.ndarray | None:
    """Up to ``count`` rotation offsets (radians, real = virtual rotated by it), best first,
    between a real and a virtual scan (ranges, metres; a :class:`~tfloc.core.laser.LaserSpec`
    and a :class:`~tfloc.paper.shape.ShapeConfig`): the highest local maxima within
    ±``max_rotation`` of their turning functions' edge-direction histograms' circular
    cross-correlation, in one compiled call; ``None`` when either scan's polygon has fewer than
    3 edges (no turning function)."""
    width = 2 * np.pi / bins
    rots, ok = _scan_rotations(
        np.asarray(real_ranges, dtype=float), np.asarray(virtual_ranges, dtype=float),
        laser.directions, float(laser.max_range), float(shape.spacing), int(shape.window),
        float(shape.straw_t), float(shape.line_threshold), bool(shape.close_through_origin),
        shape.resampling == "path", bins, skip_closure, _pair_kernel(bins, float(smoothing)),
        int(np.floor(max_rotation / width)), int(count))
    return rots if ok else None
