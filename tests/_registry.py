"""The matchers of the registry, as the generic tests see them: every matcher the project's modules
declare (``REGISTRY``, :mod:`tfloc.core.registry`) and every installed entry point of
``tfloc.matchers`` (a third party's), so that a new matcher is covered by the generic tests
without editing a test file. A matcher whose optional library is missing is
skipped with the registry's one-line reason."""

from __future__ import annotations

import pytest

from tfloc.core.matcher import (
    TRACKER,
    _registry,
    available_matchers,
    get_matcher,
    kind_of,
    solves_global,
)
from tfloc.core.tracker import has_single_scan_mode
from tfloc.errors import LibraryMissingError

NAMES = available_matchers()


def target(name: str) -> str:
    """The ``module:attr`` of a registered matcher (its declaration's or its entry point's)."""
    return _registry()[name]


#: the baselines: registered matchers whose module is one of ``baselines/``
BASELINES = [n for n in NAMES if target(n).startswith("tfloc.baselines.")]


def build(name: str, **params):
    """``get_matcher(name, **params)``, or skip the test when its library is not installed."""
    try:
        return get_matcher(name, **params)
    except LibraryMissingError as exc:
        pytest.skip(str(exc))


def kind(matcher) -> str:
    """``tracker`` (start/step, no single-scan mode, or a declared ``kind`` tracker: a matcher
    that pulls towards its guess and is meant for sequences, e.g. ``cartographer-local``),
    ``global`` (answers problems without an initial guess) or ``local``."""
    if not has_single_scan_mode(matcher) or kind_of(matcher) == TRACKER:
        return "tracker"
    return "global" if solves_global(matcher) else "local"


def single_scan(name: str):
    """The matcher ``name`` for a single-scan test, or skip it if it is a tracker."""
    matcher = build(name)
    if kind(matcher) == "tracker":
        pytest.skip("a tracker: no single-scan mode, or meant for sequences only")
    return matcher
