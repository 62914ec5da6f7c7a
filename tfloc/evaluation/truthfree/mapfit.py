"""Scan-to-map consistency: the share of a scan's returns that land on the map at an answer.

At pose (x, y, θ) each return is put into the map frame and looked up in the map's distance
field (:mod:`tfloc.maps.fields`, built once per map); it *fits* where it lies within ``tol_m``
of the map's geometry. The share of fitting returns is robust to unmapped objects (people,
furniture): they lower every tracker's share at that scan alike, which is why the verdict
compares a share with the best any tracker reached on the same scan (:mod:`.belief`).
"""

from __future__ import annotations

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.maps.fields import DistanceField

#: scans per chunk of the vectorised look-up (bounds the temporary arrays to a few MB)
CHUNK = 2048


def scan_points(ranges: np.ndarray, laser: LaserSpec) -> np.ndarray:
    """``(N, B, 2)`` sensor-frame points of ``ranges`` ``(N, B)`` (metres); NaN where a beam has
    no return."""
    r = np.asarray(ranges, dtype=float)
    ok = laser.valid(r)
    pts = laser.directions[None, :, :] * np.where(ok, r, np.nan)[:, :, None]
    return pts


def fit_shares(points: np.ndarray, poses: np.ndarray, field: DistanceField, tol_m: float) -> np.ndarray:
    """``(N,)`` share of each scan's returns within ``tol_m`` of the map (NaN for a scan
    without a return or a non-finite pose); ``points`` from :func:`scan_points`, ``poses``
    ``(N, 3)`` metres and radians in the map frame."""
    n = len(poses)
    out = np.full(n, np.nan)
    for a in range(0, n, CHUNK):
        p, q = points[a:a + CHUNK], np.asarray(poses[a:a + CHUNK], dtype=float)
        c, s = np.cos(q[:, 2])[:, None], np.sin(q[:, 2])[:, None]
        wx = q[:, 0:1] + c * p[..., 0] - s * p[..., 1]
        wy = q[:, 1:2] + s * p[..., 0] + c * p[..., 1]
        ok = np.isfinite(wx) & np.isfinite(wy)
        d = field(np.stack([np.where(ok, wx, 0.0), np.where(ok, wy, 0.0)], axis=-1))
        hits = ((d <= tol_m) & ok).sum(axis=1)
        count = ok.sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            out[a:a + CHUNK] = np.where(count > 0, hits / np.maximum(count, 1), np.nan)
    return out
