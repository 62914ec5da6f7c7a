"""A compiled point-in-area test that gives shapely's answers, for maps queried many times.

``shapely.contains_xy`` / ``intersects_xy`` cost a few microseconds per call whatever the number of
points, and ``tf`` asks one point per cost evaluation (hundreds per scan), ``tf-plus`` some 800
lattice points per scan. :class:`Rings` holds the boundary segments of a valid (Multi)Polygon
and a raster of its cells (:func:`raster_kernel`): a cell that no segment comes near lies wholly
on one side, the side of its centre, and answers by one look-up; in the other cells the crossing
parity is counted, compiled; a point closer than :data:`SURE` metres to the boundary is *unsure*
and left to shapely. So every answer is shapely's: away from the boundary the parity of a valid
polygon's rings is the interior (the rounding of the crossing test is ~1e-14 m on maps of tens
of metres, far below :data:`SURE`), and on or near the boundary, where ``contains`` and
``intersects`` differ, shapely decides. Building the raster costs more than a few shapely calls,
so :class:`~tfloc.maps.vector.VectorMap` builds it only when a matcher asks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from numba import njit
from shapely.geometry.base import BaseGeometry

SURE = 1e-7      # metres from the boundary beyond which the compiled test decides alone
CELL = 0.1       # metres: the raster's cell (larger on maps of more than MAX_CELLS cells)
MAX_CELLS = 4e6


@njit(cache=True, nogil=True)
def inside_kernel(xs: np.ndarray, ys: np.ndarray, segs: np.ndarray, sure: float) -> np.ndarray:
    """Per point ``(xs[i], ys[i])``: 1 inside, 0 outside, -1 within ``sure`` metres of a segment
    of ``segs`` ``(M, 4)`` (the rings' edges), by the crossing parity of a ray towards +x."""
    out = np.empty(xs.shape[0], dtype=np.int8)
    every = np.arange(segs.shape[0])
    for i in range(xs.shape[0]):
        out[i] = _point_code(xs[i], ys[i], segs, every, 0, segs.shape[0], sure)
    return out


@njit(cache=True, nogil=True)
def raster_kernel(segs: np.ndarray, x0: float, y0: float, res: float, nx: int,
                  ny: int) -> np.ndarray:
    """Per cell ``(ny, nx)`` of side ``res`` from ``(x0, y0)``: 1 wholly inside the rings
    ``segs``, 0 wholly outside, -1 *mixed* (every cell whose centre a segment passes within the
    cell's half-diagonal, plus a margin, and a few neighbours: found row by row along each
    segment, so the cost grows with the segments' length, not their bounding boxes). A pure cell's side is the crossing parity at its centre, counted
    row by row (the crossings of the row's line, sorted), as :func:`inside_kernel` counts it."""
    codes = np.zeros((ny, nx), dtype=np.int8)
    reach = res * math.sqrt(0.5) + 1e-9
    for m in range(segs.shape[0]):                      # mixed cells along every segment
        x1, y1, x2, y2 = segs[m, 0], segs[m, 1], segs[m, 2], segs[m, 3]
        ex, ey = x2 - x1, y2 - y1
        r0 = max(int(math.floor((min(y1, y2) - reach - y0) / res)) - 1, 0)
        r1 = min(int(math.floor((max(y1, y2) + reach - y0) / res)) + 1, ny - 1)
        for r in range(r0, r1 + 1):
            # the part of the segment within ``reach`` of the row's centre line (in y), widened
            # by ``reach``: a superset of the row's cells it comes near (marking more
            # cells mixed than needed only sends more points to the exact test)
            yc = y0 + (r + 0.5) * res
            if ey == 0.0:
                if abs(y1 - yc) > reach:
                    continue
                lo, hi = 0.0, 1.0
            else:
                ta, tb = (yc - reach - y1) / ey, (yc + reach - y1) / ey
                lo, hi = max(0.0, min(ta, tb)), min(1.0, max(ta, tb))
                if lo > hi:
                    continue
            xa, xb = x1 + lo * ex, x1 + hi * ex
            c0 = max(int(math.floor((min(xa, xb) - reach - x0) / res)), 0)   # (half a cell
            c1 = min(int(math.floor((max(xa, xb) + reach - x0) / res)), nx - 1)  # to spare)
            for c in range(c0, c1 + 1):
                codes[r, c] = -1
    xs = np.empty(segs.shape[0])
    for r in range(ny):                                  # parity of the pure cells, per row
        y = y0 + (r + 0.5) * res
        k = 0
        for m in range(segs.shape[0]):
            x1, y1, x2, y2 = segs[m, 0], segs[m, 1], segs[m, 2], segs[m, 3]
            if (y1 > y) != (y2 > y):
                xs[k] = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
                k += 1
        cross = np.sort(xs[:k])
        j = 0                                            # crossings at or left of the centre
        for c in range(nx):
            x = x0 + (c + 0.5) * res
            while j < k and cross[j] <= x:
                j += 1
            if codes[r, c] == 0 and (k - j) % 2 == 1:    # odd count to the right: inside
                codes[r, c] = 1
    return codes


@njit(cache=True, nogil=True)
def _point_code(x: float, y: float, segs: np.ndarray, items: np.ndarray, lo: int, hi: int,
                sure: float) -> int:
    """1 inside, 0 outside, -1 within ``sure`` of a segment, for one point from the segments
    ``items[lo:hi]`` (all of them for :func:`inside_kernel`; those of its raster row, every
    segment that could cross the point's horizontal or come within ``sure`` of it, for
    :func:`raster_code`)."""
    s2 = sure * sure
    inside = False
    for t in range(lo, hi):
        m = items[t]
        x1, y1, x2, y2 = segs[m, 0], segs[m, 1], segs[m, 2], segs[m, 3]
        ex, ey = x2 - x1, y2 - y1
        ll = ex * ex + ey * ey
        u = 0.0
        if ll > 0.0:
            u = min(1.0, max(0.0, ((x - x1) * ex + (y - y1) * ey) / ll))
        dx, dy = x1 + u * ex - x, y1 + u * ey - y
        if dx * dx + dy * dy <= s2:
            return -1
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * ex / ey:
            inside = not inside
    return 1 if inside else 0


@njit(cache=True, nogil=True)
def row_buckets(segs: np.ndarray, y0: float, res: float, ny: int,
                sure: float) -> tuple[np.ndarray, np.ndarray]:
    """For each raster row ``(ny,)`` the segments whose y-range, widened by ``sure``, meets the
    row: ``start`` ``(ny + 1,)`` and ``items`` (in segment order within a row)."""
    counts = np.zeros(ny + 1, dtype=np.int64)
    for m in range(segs.shape[0]):
        r0 = max(int(math.floor((min(segs[m, 1], segs[m, 3]) - sure - y0) / res)), 0)
        r1 = min(int(math.floor((max(segs[m, 1], segs[m, 3]) + sure - y0) / res)), ny - 1)
        for r in range(r0, r1 + 1):
            counts[r + 1] += 1
    for r in range(ny):
        counts[r + 1] += counts[r]
    items = np.empty(counts[ny], dtype=np.int64)
    fill = counts[:-1].copy()
    for m in range(segs.shape[0]):
        r0 = max(int(math.floor((min(segs[m, 1], segs[m, 3]) - sure - y0) / res)), 0)
        r1 = min(int(math.floor((max(segs[m, 1], segs[m, 3]) + sure - y0) / res)), ny - 1)
        for r in range(r0, r1 + 1):
            items[fill[r]] = m
            fill[r] += 1
    return counts, items


@njit(cache=True, nogil=True)
def raster_code(x: float, y: float, rings: tuple, sure: float) -> int:
    """:func:`inside_kernel`'s answer for one point, from the cell codes of :func:`raster_kernel`
    where the point's cell is pure (outside the raster: outside), else from the crossings with
    the segments of its row (:func:`_point_code`: the same answer, without testing every segment
    of the map). ``rings`` is :attr:`Rings.kernel` = ``(codes, x0, y0, res, segs, row_start,
    row_items)``."""
    codes, x0, y0, res, segs, row_start, row_items = rings
    ny, nx = codes.shape
    fx = math.floor((x - x0) / res)
    fy = math.floor((y - y0) / res)
    if not (fx >= 0.0 and fy >= 0.0 and fx < nx and fy < ny):
        return 0                                         # beyond the rings' bounds (or NaN)
    code = codes[int(fy), int(fx)]
    if code >= 0:
        return code
    return _point_code(x, y, segs, row_items, row_start[int(fy)], row_start[int(fy) + 1], sure)


@njit(cache=True, nogil=True)
def raster_inside_kernel(xs: np.ndarray, ys: np.ndarray, rings: tuple, sure: float) -> np.ndarray:
    """:func:`raster_code` of every point ``(xs[i], ys[i])``."""
    out = np.empty(xs.shape[0], dtype=np.int8)
    for i in range(xs.shape[0]):
        out[i] = raster_code(xs[i], ys[i], rings, sure)
    return out


@dataclass(frozen=True, eq=False)
class Rings:
    """The boundary of a valid Polygon or MultiPolygon ``geom`` as segments ``(M, 4)``, and a
    raster of its cells (:func:`raster_kernel`: ``codes``, cell ``res`` metres from
    ``(x0, y0)``) that answers most queries by one look-up."""

    geom: BaseGeometry
    segs: np.ndarray
    codes: np.ndarray
    x0: float
    y0: float
    res: float
    row_start: np.ndarray   # the segments of each raster row (row_buckets): where a row's start
    row_items: np.ndarray   # ... and the segments' indices

    @property
    def kernel(self) -> tuple:
        """What the compiled tests take (:func:`raster_code`)."""
        return (self.codes, self.x0, self.y0, self.res, self.segs, self.row_start, self.row_items)

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
        segs = np.ascontiguousarray(np.vstack(parts), dtype=float)
        x_min, y_min, x_max, y_max = geom.bounds
        res = max(CELL, math.sqrt((x_max - x_min) * (y_max - y_min) / MAX_CELLS))
        x0, y0 = x_min - 2 * res, y_min - 2 * res       # two cells beyond the bounds
        nx = int(math.ceil((x_max - x_min) / res)) + 4
        ny = int(math.ceil((y_max - y_min) / res)) + 4
        start, items = row_buckets(segs, y0, res, ny, SURE)
        return cls(geom, segs, raster_kernel(segs, x0, y0, res, nx, ny), x0, y0, res, start, items)

    def contains(self, xy: np.ndarray, boundary: bool) -> np.ndarray:
        """Which ``(N, 2)`` points lie in the interior (``boundary`` False: ``contains_xy``) or in
        the interior or on the boundary (True: ``intersects_xy``)."""
        x = np.ascontiguousarray(xy[:, 0], dtype=float)
        y = np.ascontiguousarray(xy[:, 1], dtype=float)
        code = raster_inside_kernel(x, y, self.kernel, SURE)
        out = code == 1
        unsure = code < 0
        if unsure.any():
            test = shapely.intersects_xy if boundary else shapely.contains_xy
            out[unsure] = test(self.geom, x[unsure], y[unsure])
        return out
