"""The per-process workspace: what a worker (or any command that runs matchers) loads once and
how it runs one matcher on one problem.

* :func:`~tfloc.io.scenario.load_dataset` — a dataset's metadata and scans by id, read once per process;
* :func:`load_matcher` — a matcher built once per process and configuration
  (:func:`tfloc.core.matcher.get_matcher`, registered names and ``module:Class`` alike);
* :func:`problem_of` — the :class:`~tfloc.core.problem.Problem` of a scan (the dataset's map,
  loaded once, or the scan's reference scan);
* :func:`warm` / :func:`warm_tracker` — the untimed warm-up before a matcher's first timed call
  on a map, or a tracker's first timed step;
* :func:`timed` — the one timer: a call timed by CPU time (``time.process_time``: this process,
  all its threads; workers run every library on one thread) and wall time;
  :func:`timed_localize` and :func:`timed_step` time a ``localize`` and a tracker's ``step``.

The runner's tasks, the tracking loop, the timing pass, the report's pictures and ``tfloc
localize`` all use these, so a scan is posed, warmed and timed the same way everywhere.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from functools import lru_cache

from tfloc.core.matcher import Matcher, get_matcher
from tfloc.core.problem import Estimate, Problem
from tfloc.core.result import OK, Status, StatusKind
from tfloc.core.tracker import Tracker, kept_prediction
from tfloc.io.scenario import Scan, Scenario, map_for

_MAPS: dict = {}


@lru_cache(maxsize=32)
def load_matcher(name: str, params_json: str = "{}") -> Matcher:
    """A matcher built once per process (``params_json``: its parameters as sorted JSON)."""
    return get_matcher(name, **json.loads(params_json))


def use_map(scenario: Scenario, map_) -> None:
    """Localize ``scenario``'s scans in ``map_`` instead of the map its ``scenario.json`` names
    (``tfloc localize --map``)."""
    _MAPS[scenario.map_path] = map_


def map_of(scenario: Scenario, scan: Scan):
    """The map ``scan`` is localized in: the dataset's map, loaded once per process, or the
    scan's reference scan (:func:`tfloc.io.scenario.map_for`)."""
    return map_for(scenario, scan, _MAPS)


def problem_of(scenario: Scenario, scan: Scan, initial=...) -> Problem:
    """The :class:`Problem` of one scan: the dataset's map (loaded once per process) or the
    scan's reference scan; ``initial`` overrides the scan's guess (a tracker's prediction)."""
    guess = scan.initial if initial is ... else initial
    return Problem(map_of(scenario, scan), scenario.laser, scan.ranges, guess,
                   where=f"{scenario.scans_path}:{scan.line}")


def warm(matcher: Matcher, problem: Problem) -> None:
    """Untimed warm-up: ``matcher.prepare(problem)`` (map-only structures) if the matcher has one,
    then one ``score`` at the initial pose, if there are both (kernels compiled or loaded from
    numba's cache)."""
    prepare = getattr(matcher, "prepare", None)
    if prepare is not None:
        prepare(problem)
    if problem.initial is not None and callable(getattr(matcher, "score", None)):
        matcher.score(problem, problem.initial)


def warm_tracker(tracker: Tracker, map_, laser, ranges, pose) -> None:
    """Untimed warm-up of a tracker before ``start``: its ``warm`` if it has one (errors are
    left to the timed steps to report)."""
    warm_ = getattr(tracker, "warm", None)
    if warm_ is None:
        return
    try:
        warm_(map_, laser, ranges, pose)
    except Exception:  # noqa: BLE001 - the timed steps report what is wrong
        pass


@dataclass(frozen=True)
class Timed:
    """One timed call: the estimate, its wall time and its CPU time (seconds)."""

    estimate: Estimate
    wall_s: float
    cpu_s: float


def timed(call, *args, **kwargs) -> Timed:
    """``call(*args, **kwargs)`` (an :class:`Estimate`) timed by wall and CPU time; exceptions
    propagate."""
    t0, c0 = time.perf_counter(), time.process_time()
    est = call(*args, **kwargs)
    return Timed(est, time.perf_counter() - t0, time.process_time() - c0)


def timed_localize(matcher: Matcher, problem: Problem) -> Timed:
    """``matcher.localize(problem)``, timed."""
    return timed(matcher.localize, problem)


def timed_step(tracker: Tracker, ranges, odom_delta, stamp: float, where: str) -> Timed:
    """One tracker step, timed."""
    return timed(tracker.step, ranges, odom_delta, stamp, where=where)


def status_of(est: Estimate) -> Status:
    """``failed`` when the matcher declined (:attr:`Estimate.declined`) or a tracker kept its
    prediction, else ``ok``; whether it converged is reported separately."""
    return Status(StatusKind.FAILED) if est.declined or kept_prediction(est) else OK
