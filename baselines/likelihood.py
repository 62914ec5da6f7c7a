"""A likelihood field of a map (Thrun's "likelihood field"; Olson's rasterised lookup table).

The map's geometry is rasterised at ``resolution`` metres, ``scipy.ndimage.distance_transform_edt``
gives every cell its distance to the nearest wall, and a beam endpoint at distance ``d`` has
likelihood ``exp(-d² / 2σ²)``. The grid covers the map's bounds plus ``pad`` metres on every side;
cells more than 1 m beyond the map's bounds have likelihood 0 (a search uses that band to look up
shifted endpoints by integer index without clipping every lookup).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.ndimage import distance_transform_edt, map_coordinates, maximum_filter

from tfloc.maps.cache import cached

_EDT_MARGIN_M = 1.0  # distance transform computed on bounds + 1 m; farther cells are "far" anyway


@dataclass(frozen=True, eq=False)
class LikelihoodField:
    """Per-cell distance to the map (metres) and likelihood, row = y index, column = x index.

    Attributes:
        distance: ``(H, W)`` float32 metres to the nearest map geometry (capped beyond the map).
        likelihood: ``(H, W)`` float32 ``exp(-d² / 2σ²)``.
        origin: world ``(x, y)`` of cell ``[0, 0]``'s centre, metres.
        resolution: cell size, metres.
        sigma: σ of the likelihood, metres.
    """

    distance: np.ndarray
    likelihood: np.ndarray
    origin: tuple[float, float]
    resolution: float
    sigma: float

    @property
    def shape(self) -> tuple[int, int]:
        return self.likelihood.shape  # type: ignore[return-value]

    def cells(self, xy: np.ndarray) -> np.ndarray:
        """Nearest integer cell ``(..., 2)`` = (column, row) of world points ``(..., 2)``."""
        return np.rint((np.asarray(xy) - self.origin) / self.resolution).astype(np.int64)

    def flat_index(self, xy: np.ndarray) -> np.ndarray:
        """Flat indices into ``likelihood.ravel()`` of the nearest cells, clipped to the grid."""
        c = self.cells(xy)
        h, w = self.shape
        return np.clip(c[..., 1], 0, h - 1) * w + np.clip(c[..., 0], 0, w - 1)

    def distance_at(self, xy: np.ndarray) -> np.ndarray:
        """Bilinearly interpolated distance (metres) to the map at world points ``(N, 2)``."""
        g = (np.asarray(xy, dtype=float) - self.origin) / self.resolution
        return map_coordinates(self.distance, (g[:, 1], g[:, 0]), order=1, mode="nearest")

    def likelihood_at(self, xy: np.ndarray) -> np.ndarray:
        """``exp(-d² / 2σ²)`` with the interpolated distance ``d`` at world points ``(N, 2)``."""
        d = self.distance_at(xy)
        return np.exp(-0.5 * (d / self.sigma) ** 2)

    def max_pooled(self, cells: int) -> np.ndarray:
        """Olson's low-resolution table: cell ``[r, c]`` holds the largest likelihood over the
        ``cells`` × ``cells`` block starting at ``[r, c]``, so a sum of its lookups bounds from above
        the score of every translation within that block."""
        return _pooled(self, int(cells))

    @cached_property
    def _pool_cache(self) -> dict[int, np.ndarray]:
        return {}


def _pooled(field: LikelihoodField, k: int) -> np.ndarray:
    cache = field._pool_cache
    if k not in cache:
        if k % 2 == 0:
            raise ValueError(f"pooling window must be odd, got {k}")
        cache[k] = maximum_filter(field.likelihood, size=k, origin=-(k // 2), mode="constant", cval=0.0)
    return cache[k]


def build_likelihood_field(map_: object, resolution: float, sigma: float, pad: float) -> LikelihoodField:
    """Rasterise ``map_`` (any :class:`~tfloc.maps.base.Map`) into a :class:`LikelihoodField`."""
    x0, y0, x1, y1 = map_.bounds  # type: ignore[attr-defined]
    pts, _ = map_.sample_points(resolution / 2.0)  # type: ignore[attr-defined]
    m = int(np.ceil(_EDT_MARGIN_M / resolution))
    p = int(np.ceil(pad / resolution))
    w_in = int(np.ceil((x1 - x0) / resolution)) + 1 + 2 * m
    h_in = int(np.ceil((y1 - y0) / resolution)) + 1 + 2 * m
    inner_origin = np.array([x0, y0]) - m * resolution
    c = np.rint((pts - inner_origin) / resolution).astype(np.int64)
    keep = (c[:, 0] >= 0) & (c[:, 0] < w_in) & (c[:, 1] >= 0) & (c[:, 1] < h_in)
    free = np.ones((h_in, w_in), dtype=bool)
    free[c[keep, 1], c[keep, 0]] = False
    dist = (distance_transform_edt(free) * resolution).astype(np.float32)
    far = np.float32(max(_EDT_MARGIN_M, 10.0 * sigma))
    dist = np.pad(np.minimum(dist, far), p, mode="constant", constant_values=far)
    lik = np.exp(-0.5 * (dist / np.float32(sigma)) ** 2).astype(np.float32)
    origin = inner_origin - p * resolution
    return LikelihoodField(dist, lik, (float(origin[0]), float(origin[1])), float(resolution), float(sigma))


def likelihood_field(map_: object, resolution: float, sigma: float, pad: float) -> LikelihoodField:
    """The cached :func:`build_likelihood_field` of ``map_`` (built once per map and parameters)."""
    key = ("likelihood", round(resolution, 9), round(sigma, 9), round(pad, 6))
    return cached(map_, key, lambda: build_likelihood_field(map_, resolution, sigma, pad))
