"""Maps: the :class:`Map` protocol, :class:`VectorMap` (segments) and :class:`GridMap` (occupancy grid)."""

from .base import Map
from .grid import GridMap
from .vector import VectorMap

__all__ = ["GridMap", "Map", "VectorMap"]
