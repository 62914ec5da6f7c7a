"""Cartographer, ported from its source (Apache-2.0): ``cartographer`` (:mod:`.tracker`), the whole
pure-localization loop (local SLAM on its own submaps :mod:`._local` / :mod:`._submaps`, frozen
submaps of the map and the constraint builder :mod:`._frozen`, the sparse pose optimisation
:mod:`._optimize`; docs/baselines/cartographer.md), and ``cartographer-local`` (:mod:`.matcher`),
its local scan matcher run against the map (docs/baselines/cartographer-local.md). Shared: the
probability grid and Ceres' bicubic interpolation (:mod:`._grid`), the scan filters
(:mod:`._filters`), the real-time correlative scan matcher (:mod:`._csm`) and the Ceres scan
matcher (:mod:`._ceres`).
"""

from ._config import Config as LocalizationConfig
from .matcher import CartographerLocalMatcher, Config
from .tracker import CartographerTracker

__all__ = ["CartographerLocalMatcher", "CartographerTracker", "Config", "LocalizationConfig"]
