"""Cartographer's 2D local scan matching against a map: ``cartographer-local``
(:mod:`.matcher`), its probability grid and Ceres' bicubic interpolation (:mod:`._grid`), its scan
filters (:mod:`._filters`) and its real-time correlative scan matcher (:mod:`._csm`). A port of
Cartographer's source (Apache-2.0); what it is and where it departs: docs/baselines/cartographer-local.md.
"""

from .matcher import CartographerLocalMatcher, Config

__all__ = ["CartographerLocalMatcher", "Config"]
