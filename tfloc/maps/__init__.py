"""Maps: the :class:`Map` protocol, :class:`VectorMap` (segments) and, later, ``GridMap``."""

from .base import Map
from .vector import VectorMap

__all__ = ["Map", "VectorMap"]
