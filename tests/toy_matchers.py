"""Toy matchers for harness tests (imported by spawned workers as ``toy_matchers:Class``)."""

from __future__ import annotations

import math
import os
import time

import numpy as np

from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate, Problem


class Stay:
    """Returns the initial pose; objective = distance to the initial pose."""

    name = "stay"

    def __init__(self, sleep_s: float = 0.0) -> None:
        self.sleep_s = sleep_s

    def localize(self, problem: Problem) -> Estimate:
        time.sleep(self.sleep_s)
        return Estimate(problem.initial, True, 1, 1)

    def score(self, problem: Problem, pose: Pose) -> float:
        return pose.distance_to(problem.initial)


class SlowStay(Stay):
    """:class:`Stay` taking 0.25 s per scan, so that a run can be killed mid-way (resume test)."""

    name = "slow-stay"

    def __init__(self, sleep_s: float = 0.25) -> None:
        super().__init__(sleep_s)


class ThreadsInfo(Stay):
    """:class:`Stay` reporting the thread limits its worker process was started with."""

    def localize(self, problem: Problem) -> Estimate:
        return Estimate(problem.initial, True, 1, 1, {"omp_threads": os.environ.get("OMP_NUM_THREADS"),
                                                      "numba_threads": os.environ.get("NUMBA_NUM_THREADS")})


class _EveryNth(Stay):
    """:class:`Stay` that misbehaves (:meth:`act`) on every ``every``-th call in a worker."""

    def __init__(self, every: int = 2) -> None:
        super().__init__()
        self.every, self.calls = every, 0

    def act(self) -> None:
        raise NotImplementedError

    def localize(self, problem: Problem) -> Estimate:
        self.calls += 1
        if self.calls % self.every == 0:
            self.act()
        return super().localize(problem)


class Raises(_EveryNth):
    """Raises on every ``fail_every``-th call in a worker (a data-dependent crash)."""

    def __init__(self, fail_every: int = 2) -> None:
        super().__init__(fail_every)

    def act(self) -> None:
        raise ValueError("toy failure\nwith a second line")


class Hangs(_EveryNth):
    """Hangs (sleeps far past any time limit) on every ``hang_every``-th call in a worker."""

    def __init__(self, hang_every: int = 2) -> None:
        super().__init__(hang_every)

    def act(self) -> None:
        time.sleep(3600)


class TwoMinima:
    """An objective with a global minimum 0 at ``init + to_true`` (the truth, by construction of
    the test dataset) and a second minimum of value ``false_value`` at ``init + to_false``.
    ``localize`` returns the second one, so the outcome is known: a ``local-optimum`` when
    ``false_value`` > 0, ``ambiguous`` when it is ≤ 0."""

    name = "two-minima"

    def __init__(self, to_true=(0.0, 0.0), to_false=(1.0, 0.0), false_value: float = 0.5) -> None:
        self.to_true, self.to_false, self.false_value = np.array(to_true), np.array(to_false), false_value

    def _at(self, problem: Problem, d) -> Pose:
        return Pose(problem.initial.x + d[0], problem.initial.y + d[1], problem.initial.theta)

    def localize(self, problem: Problem) -> Estimate:
        return Estimate(self._at(problem, self.to_false), True, 3, 10)

    def score(self, problem: Problem, pose: Pose) -> float:
        t, f = self._at(problem, self.to_true), self._at(problem, self.to_false)
        return min(pose.distance_to(t) + abs(math.remainder(pose.theta - t.theta, math.tau)),
                   pose.distance_to(f) + self.false_value)


class Flaky(Stay):
    """:class:`Stay` that raises while the environment variable ``TFLOC_TOY_FAIL`` is set in its
    worker (a bug that a fix removes: ``--retry-errors`` then runs its tasks again)."""

    def localize(self, problem: Problem) -> Estimate:
        if os.environ.get("TFLOC_TOY_FAIL"):
            raise RuntimeError("toy bug")
        return super().localize(problem)


_COMPILED = False  # per process, as numba's kernels are once compiled or loaded


class ColdStart(Stay):
    """:class:`Stay` whose first ``localize`` in a process takes ``first_s`` (a kernel compiled on
    a loaded machine), every later one nothing."""

    name = "cold-start"

    def __init__(self, first_s: float = 2.0) -> None:
        super().__init__(0.0)
        self.first_s = first_s

    def localize(self, problem: Problem) -> Estimate:
        global _COMPILED
        if not _COMPILED:
            time.sleep(self.first_s)
            _COMPILED = True
        return super().localize(problem)
