"""Maps: the :class:`Map` protocol, :class:`VectorMap` (segments) and :class:`GridMap` (occupancy grid)."""

from tfloc.core.map import Map
from tfloc.maps.grid import GridMap
from tfloc.maps.vector import VectorMap

__all__ = ["GridMap", "Map", "VectorMap"]
