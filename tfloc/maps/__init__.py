"""Maps: :class:`VectorMap` (segments), :class:`GridMap` (occupancy grid), the virtual sensor's
kernels, the distance field and the per-map cache. The protocol they follow is :class:`tfloc.core.map.Map`."""

from tfloc.core.map import Map
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap

__all__ = ["GridMap", "Map", "VectorMap"]
