"""What a matcher says about itself beyond its answers: its method family and its own confidence.

A matcher class may declare

* ``METHOD``: the method it implements (default: its registered name's ``name``). Two trackers of
  one method (AMCL's port and Nav2's wheel, ``kiss-icp`` and its adaptive tracker) are not
  independent witnesses of each other: the truth-free consensus counts one vote per method
  (:mod:`tfloc.evaluation.truthfree.consensus`). ``METHOD = None``: it never looks at the map
  (dead reckoning) and does not vote.
* ``CONFIDENCE``: the ``info`` key in which each answer reports the matcher's own confidence, and
  whether a higher value means surer (:class:`Confidence`); ``None`` where it reports none. The
  suite reads it as a lost-detector (:mod:`tfloc.evaluation.selfassess`).

Labels, presets and ``base[key=value]`` names resolve to their registered class
(:func:`tfloc.core.matcher.factory_of`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from tfloc.errors import TflocError

from .matcher import factory_of


@dataclass(frozen=True)
class Confidence:
    """A matcher's own confidence: ``info[key]`` per answer; ``higher_is_surer`` False where a
    higher value means less sure (a residual, a covariance). ``about`` says what it is, for the
    report."""

    key: str
    higher_is_surer: bool
    about: str = ""

    def lostness(self, value: float) -> float:
        """``value`` turned so that higher means more likely lost (what a ROC ranks by)."""
        return -value if self.higher_is_surer else value


def _factory(label: str):
    try:
        return factory_of(label)
    except (TflocError, ImportError, OSError):
        return None


@cache
def method_of(label: str) -> str | None:
    """The method family of a matcher label (``None``: it does not look at the map)."""
    f = _factory(label)
    if f is None:
        return label
    if "METHOD" in dir(f):
        return f.METHOD
    return getattr(f, "name", None) or label


@cache
def confidence_of(label: str) -> Confidence | None:
    """The confidence a matcher label reports in its answers' ``info``, or ``None``."""
    f = _factory(label)
    c = getattr(f, "CONFIDENCE", None) if f is not None else None
    return c if isinstance(c, Confidence) else None
