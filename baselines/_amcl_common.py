"""What the two AMCL trackers share: ``amcl`` (the port, :mod:`tfloc.baselines.amcl`) and
``amcl-wheel`` (:mod:`tfloc.baselines.amcl_wheel`). tfloc's own code around Nav2's filter (MIT,
as the rest of tfloc: neither a translation of nav2_amcl nor a use of the GPL-3.0 wheel).

* :func:`amcl_grid`: the grid AMCL runs on, a grid map as given, a vector map rasterised at 5 cm
  (as a user exports it for Nav2).
"""

from __future__ import annotations

from tfloc.core.map import Map
from tfloc.maps.build import rasterize
from tfloc.maps.cache import cached
from tfloc.maps.grid import GridMap

#: Grid resolution (m) a vector map is rasterised at, as a user would export it for Nav2
VECTOR_MAP_RESOLUTION = 0.05


def amcl_grid(map_: Map) -> GridMap:
    """The grid AMCL runs on: ``map_`` itself if it is a grid, else rasterised at 5 cm (cached per map)."""
    if isinstance(map_, GridMap):
        return map_
    return cached(map_, ("amcl-grid", VECTOR_MAP_RESOLUTION), lambda: rasterize(map_, VECTOR_MAP_RESOLUTION))
