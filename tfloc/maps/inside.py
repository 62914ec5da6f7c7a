"""A compiled point-in-area test that gives shapely's answers, for many single-point queries.

``shapely.contains_xy`` / ``intersects_xy`` cost a few microseconds per call whatever the number of
points, and ``tf`` asks one point per cost evaluation (hundreds per scan); for many points at
once shapely's indexed test is the faster and answers (more than :data:`FEW` points). :class:`Rings` holds the
boundary segments of a valid (Multi)Polygon and answers by crossing parity, compiled; a point
closer than :data:`SURE` metres to the boundary is *unsure* and left to shapely, so every answer is
shapely's: away from the boundary the parity of a valid polygon's rings is the interior (the
rounding of the crossing test is ~1e-14 m on maps of tens of metres, far below :data:`SURE`), and
on or near the boundary, where ``contains`` and ``intersects`` differ, shapely decides.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from numba import njit
from shapely.geometry.base import BaseGeometry

SURE = 1e-7  # metres from the boundary beyond which the compiled test decides alone
FEW = 8      # queries of more points go to shapely (its prepared geometry is indexed)


@njit(cache=True, nogil=True)
def inside_kernel(xs: np.ndarray, ys: np.ndarray, segs: np.ndarray, sure: float) -> np.ndarray:
    """Per point ``(xs[i], ys[i])``: 1 inside, 0 outside, -1 within ``sure`` metres of a segment
    of ``segs`` ``(M, 4)`` (the rings' edges), by the crossing parity of a ray towards +x."""
    out = np.empty(xs.shape[0], dtype=np.int8)
    s2 = sure * sure
    for i in range(xs.shape[0]):
        x, y = xs[i], ys[i]
        inside = False
        near = False
        for m in range(segs.shape[0]):
            x1, y1, x2, y2 = segs[m, 0], segs[m, 1], segs[m, 2], segs[m, 3]
            ex, ey = x2 - x1, y2 - y1
            ll = ex * ex + ey * ey
            u = 0.0
            if ll > 0.0:
                u = min(1.0, max(0.0, ((x - x1) * ex + (y - y1) * ey) / ll))
            dx, dy = x1 + u * ex - x, y1 + u * ey - y
            if dx * dx + dy * dy <= s2:
                near = True
                break
            if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * ex / ey:
                inside = not inside
        out[i] = -1 if near else (1 if inside else 0)
    return out


@dataclass(frozen=True, eq=False)
class Rings:
    """The boundary of a valid Polygon or MultiPolygon ``geom`` as segments ``(M, 4)``."""

    geom: BaseGeometry
    segs: np.ndarray

    @classmethod
    def of(cls, geom: BaseGeometry) -> Rings | None:
        """The rings of ``geom``, or ``None`` when the compiled test does not apply (not a valid,
        non-empty Polygon or MultiPolygon): then ask shapely."""
        if geom.geom_type not in ("Polygon", "MultiPolygon") or geom.is_empty \
                or not shapely.is_valid(geom):
            return None
        parts = []
        for ring in shapely.get_parts(shapely.get_rings(shapely.get_parts(geom))):
            c = shapely.get_coordinates(ring)
            parts.append(np.hstack((c[:-1], c[1:])))
        return cls(geom, np.ascontiguousarray(np.vstack(parts), dtype=float))

    def contains(self, xy: np.ndarray, boundary: bool) -> np.ndarray:
        """Which ``(N, 2)`` points lie in the interior (``boundary`` False: ``contains_xy``) or in
        the interior or on the boundary (True: ``intersects_xy``)."""
        x = np.ascontiguousarray(xy[:, 0], dtype=float)
        y = np.ascontiguousarray(xy[:, 1], dtype=float)
        test = shapely.intersects_xy if boundary else shapely.contains_xy
        if len(x) > FEW:       # shapely's indexed test is the faster for many points
            return test(self.geom, x, y)
        code = inside_kernel(x, y, self.segs, SURE)
        out = code == 1
        unsure = code < 0
        if unsure.any():
            out[unsure] = test(self.geom, x[unsure], y[unsure])
        return out
