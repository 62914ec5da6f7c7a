# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/pf/pf_pdf.c``: Nav2's random numbers, compiled with numba.

* ``drand48``/``srand48``: the C library's 48-bit linear congruential stream (POSIX: ``x ← (0x5DEECE66D
  x + 0xB) mod 2⁴⁸``, a draw is ``x / 2⁴⁸``; ``srand48(s)`` sets ``x = s₃₂ · 2¹⁶ + 0x330E``), the
  stream every draw of Nav2's filter comes from. Its state is a ``(1,)`` uint64 array owned by
  one filter, so that runs repeat bit for bit (in Nav2 it is process-wide).
* ``ran_gaussian``: ``pf_ran_gaussian``, the polar Box–Muller method (two draws or more per number).
* ``gaussian_samples``: ``pf_pdf_gaussian_alloc`` + ``pf_pdf_gaussian_sample``: the covariance split
  into rotation and variances by ``eig3.c``'s symmetric eigen decomposition (:mod:`.eig3`), one
  Gaussian draw per axis, rotated.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .eig3 import eigen_decomposition

_A = np.uint64(0x5DEECE66D)
_C = np.uint64(0xB)
_MASK = np.uint64((1 << 48) - 1)
_LOW32 = np.uint64(0xFFFFFFFF)
_SEED_LOW = np.uint64(0x330E)
_SHIFT = np.uint64(16)
_UNIT = 2.0 ** -48


def new_stream(seed: int) -> np.ndarray:
    """A fresh stream state ``srand48(seed)`` (the low 32 bits of ``seed``, as the C library)."""
    state = np.zeros(1, dtype=np.uint64)
    srand48(state, seed)
    return state


@njit(cache=True, nogil=True)
def srand48(state: np.ndarray, seed: int) -> None:
    """``srand48(seed)``: only the low 32 bits of ``seed`` count."""
    state[0] = ((np.uint64(seed) & _LOW32) << _SHIFT) | _SEED_LOW


@njit(cache=True, nogil=True)
def drand48(state: np.ndarray) -> float:
    """The next draw in [0, 1) (exactly ``x / 2⁴⁸``, as glibc's ``erand48`` builds it)."""
    x = (state[0] * _A + _C) & _MASK
    state[0] = x
    return float(x) * _UNIT


@njit(cache=True, nogil=True)
def ran_gaussian(state: np.ndarray, sigma: float) -> float:
    """``pf_ran_gaussian``: a zero-mean normal number of standard deviation ``sigma``."""
    while True:
        r = drand48(state)
        while r == 0.0:
            r = drand48(state)
        x1 = 2.0 * r - 1.0
        r = drand48(state)
        while r == 0.0:
            r = drand48(state)
        x2 = 2.0 * r - 1.0
        w = x1 * x1 + x2 * x2
        if not (w > 1.0 or w == 0.0):
            break
    return sigma * x2 * math.sqrt(-2.0 * math.log(w) / w)


@njit(cache=True, nogil=True)
def gaussian_samples(state: np.ndarray, mean: np.ndarray, cov: np.ndarray, n: int) -> np.ndarray:
    """``n`` poses ``(n, 3)`` drawn as ``pf_init`` draws them from ``pf_pdf_gaussian_t``:
    ``x = mean + R · (N(0, σ₀), N(0, σ₁), N(0, σ₂))`` with ``cov = R diag(σ²) Rᵀ``."""
    R, d = eigen_decomposition(cov)
    cd = np.sqrt(d)
    out = np.empty((n, 3))
    r = np.empty(3)
    for k in range(n):
        for i in range(3):
            r[i] = ran_gaussian(state, cd[i])
        for i in range(3):
            x = mean[i]
            for j in range(3):
                x += R[i, j] * r[j]
            out[k, i] = x
    return out
