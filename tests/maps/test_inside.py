"""The compiled point-in-area test (tfloc.maps.inside) answers exactly as shapely does, on and off
the boundary, for the maps' free space (with and without clearance) and mapped area."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from _paths import ROOT
from shapely.geometry import Polygon, box

from tfloc.io.maps import load_map
from tfloc.maps import inside
from tfloc.maps.inside import Rings
from tfloc.maps.vector import VectorMap


def _points(geom, rng: np.random.Generator, n: int) -> np.ndarray:
    """Random points over the bounds, plus every vertex, edge midpoints and points 1e-12 … 1e-3
    m off the edges (both sides)."""
    x0, y0, x1, y1 = geom.bounds
    pts = [rng.uniform((x0 - 1, y0 - 1), (x1 + 1, y1 + 1), (n, 2))]
    c = shapely.get_coordinates(shapely.get_rings(shapely.get_parts(geom)))
    pts.append(c)
    a, b = c[:-1], c[1:]
    mid = 0.5 * (a + b)
    e = b - a
    length = np.hypot(e[:, 0], e[:, 1])[:, None]
    normal = np.column_stack((-e[:, 1], e[:, 0])) / np.where(length > 0, length, 1.0)
    for d in (1e-12, 1e-9, 1e-7, 1e-6, 1e-3):
        pts += [mid + d * normal, mid - d * normal]
    pts.append(np.column_stack((rng.uniform(x0, x1, n), np.full(n, c[0, 1]))))  # a vertex's row
    return np.vstack(pts)


def _maps() -> list[VectorMap]:
    maps = [VectorMap(outline=box(0, 0, 4, 3), obstacles=(box(1, 1, 2, 2),))]
    for name in ("office-1.geojson", "office-2.geojson", "office-3.geojson", "test-room.geojson"):
        path = ROOT / "data" / "maps" / name
        if path.exists():
            maps.append(load_map(path))
    return maps


@pytest.mark.parametrize("cell", [0.1, 0.37])
@pytest.mark.parametrize("index", range(5))
def test_is_free_and_in_bounds_equal_shapely(index: int, cell: float,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    maps = _maps()
    if index >= len(maps):
        pytest.skip("map not bundled")
    m = maps[index]
    rng = np.random.default_rng(index)
    monkeypatch.setattr(inside, "CELL", cell)
    assert m.free_rings(0.0) is None and m.area_rings() is None   # built only when asked
    m.area_rings(build=True)
    for clearance in (0.0, 0.1, 0.3):
        m.free_rings(clearance, build=True)
        free = m._free_space(clearance)
        xy = _points(free, rng, 4000)
        expect = shapely.contains_xy(free, xy[:, 0], xy[:, 1])
        np.testing.assert_array_equal(m.is_free(xy, clearance), expect)
        np.testing.assert_array_equal(np.concatenate([m.is_free(p[None], clearance) for p in xy[:300]]),
                                      expect[:300])
        rings = m.free_rings(clearance)
        assert rings is not None and rings.res == cell
        assert (rings.codes >= 0).mean() > 0.25         # most cells are answered by the raster
        # points on the raster's cell edges and corners
        edges = np.stack(np.meshgrid(rings.x0 + rings.res * np.arange(rings.codes.shape[1]),
                                     rings.y0 + rings.res * np.arange(rings.codes.shape[0])),
                         axis=-1).reshape(-1, 2)
        np.testing.assert_array_equal(m.is_free(edges, clearance),
                                      shapely.contains_xy(free, edges[:, 0], edges[:, 1]))
    xy = _points(m.area, rng, 4000)
    np.testing.assert_array_equal(m.in_bounds(xy), shapely.intersects_xy(m.area, xy[:, 0], xy[:, 1]))


def test_rings_decline_what_they_cannot_answer() -> None:
    bowtie = Polygon([(0, 0), (1, 1), (1, 0), (0, 1)])     # invalid: self-intersecting
    assert Rings.of(bowtie) is None
    assert Rings.of(shapely.LineString([(0, 0), (1, 1)])) is None
    assert Rings.of(Polygon()) is None
    assert Rings.of(box(0, 0, 1, 1)) is not None
