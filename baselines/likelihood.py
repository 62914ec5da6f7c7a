"""A likelihood field of a map (Thrun's "likelihood field"; Olson's rasterised lookup table).

Built on the map's distance field (:mod:`tfloc.maps.fields`, capped at 1 m or 10 σ): a beam
endpoint at distance ``d`` from the map has likelihood ``exp(-d² / 2σ²)``. The grid reaches
``pad`` metres beyond the capped band around the map's bounds, where the likelihood is
``exp(-cap² / 2σ²)`` ≈ 0; a search uses that band to look up shifted endpoints by integer index
without clipping every lookup.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.ndimage import maximum_filter

from tfloc.maps.cache import cached
from tfloc.maps.fields import DistanceField, distance_field

_CAP_M = 1.0  # distances beyond 1 m (or 10 σ) are "far": their likelihood is ~0 either way


@dataclass(frozen=True, eq=False)
class LikelihoodField:
    """The likelihood ``exp(-d² / 2σ²)`` of the map's :class:`DistanceField` ``d``.

    Attributes:
        field: the distance field (metres), whose grid this shares.
        likelihood: ``(H, W)`` float32 likelihood per cell, row = y index, column = x index.
        sigma: σ of the likelihood, metres.
    """

    field: DistanceField
    likelihood: np.ndarray
    sigma: float
    _pooled: dict[int, np.ndarray] = field(default_factory=dict, repr=False)

    @property
    def shape(self) -> tuple[int, int]:
        return self.likelihood.shape  # type: ignore[return-value]

    @property
    def resolution(self) -> float:
        return self.field.resolution

    def cells(self, xy: np.ndarray) -> np.ndarray:
        """Nearest integer cell ``(..., 2)`` = (column, row) of world points ``(..., 2)``."""
        return self.field.cells(xy)

    def distance_at(self, xy: np.ndarray) -> np.ndarray:
        """Bilinearly interpolated distance (metres) to the map at world points ``(N, 2)``."""
        return self.field.interpolate(xy)

    def likelihood_at(self, xy: np.ndarray) -> np.ndarray:
        """``exp(-d² / 2σ²)`` with the interpolated distance ``d`` at world points ``(N, 2)``."""
        d = self.distance_at(xy)
        return np.exp(-0.5 * (d / self.sigma) ** 2)

    def max_pooled(self, cells: int) -> np.ndarray:
        """Olson's low-resolution table: cell ``[r, c]`` holds the largest likelihood over the
        ``cells`` × ``cells`` block starting at ``[r, c]``, so a sum of its lookups bounds from above
        the score of every translation within that block (``cells`` odd)."""
        k = int(cells)
        if k not in self._pooled:
            if k % 2 == 0:
                raise ValueError(f"pooling window must be odd, got {k}")
            self._pooled[k] = maximum_filter(self.likelihood, size=k, origin=-(k // 2), mode="constant",
                                             cval=0.0)
        return self._pooled[k]


def likelihood_field(map_: object, resolution: float, sigma: float, pad: float) -> LikelihoodField:
    """The likelihood field of ``map_`` (any :class:`~tfloc.core.map.Map`), built once per map and
    parameters: cells of ``resolution`` metres reaching ``pad`` metres beyond the capped band."""
    def build() -> LikelihoodField:
        f = distance_field(map_, resolution, max(_CAP_M, 10.0 * sigma), pad)
        lik = np.exp(-0.5 * (f.distance / np.float32(sigma)) ** 2).astype(np.float32)
        return LikelihoodField(f, lik, float(sigma))

    return cached(map_, ("likelihood", round(resolution, 9), round(sigma, 9), round(pad, 6)), build)
