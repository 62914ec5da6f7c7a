"""The paper's compiled pose search (``tf``, ``tf-best``) gives the answers of its step-by-step
Python code: bit for bit, or up to Python where a bound decides; the simplex's random
directions drawn at once equal those drawn one by one."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _paths import SCEN
from _tf_cases import TRUE, noisy_scan
from _tf_oracles import step_by_step_tf

from tfloc.core.pose import Pose
from tfloc.harness.workspace import problem_of
from tfloc.io.scenario import load_dataset


def _office_problems(count: int):
    """The first ``count`` scans of each offset cell of detail-1 (the furnished office)."""

    scenario, scans = load_dataset(str(SCEN / "detail-1"))
    seen: dict[str, int] = {}
    out = []
    for s in scans.values():
        if seen.get(s.group, 0) < count:
            seen[s.group] = seen.get(s.group, 0) + 1
            out.append(problem_of(scenario, s))
    return out


@pytest.mark.parametrize("name", ["tf", "tf-best"])
def test_compiled_tf_search_gives_the_python_answers(name: str,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    from tfloc.core.matcher import get_matcher

    m = get_matcher(name)
    for problem in _office_problems(1):
        fast = m.localize(problem)
        with monkeypatch.context() as mp:
            step_by_step_tf(mp)
            slow = m.localize(problem)
        assert (fast.pose, fast.converged, fast.iterations, fast.evaluations, fast.info) == \
            (slow.pose, slow.converged, slow.iterations, slow.evaluations, slow.info)


def test_simplex_directions_drawn_at_once_equal_one_by_one() -> None:
    rng = np.random.default_rng(7)
    one_by_one = [rng.uniform(0.0, 2.0 * math.pi) for _ in range(8)]
    assert np.array_equal(np.random.default_rng(7).uniform(0.0, 2.0 * math.pi, 8), one_by_one)



def test_compiled_tf_search_gives_up_to_python_near_boundaries(
        test_room, lms200, monkeypatch: pytest.MonkeyPatch) -> None:
    """With the compiled free test unsure within 0.5 m of the free space's boundary, the compiled
    search gives up where its simplex comes near a wall (and Function1 asks shapely): the
    answers stay the Python ones."""
    from tfloc.core.matcher import get_matcher
    from tfloc.core.problem import Problem
    from tfloc.paper import matcher as paper_matcher

    m = get_matcher("tf")
    monkeypatch.setattr(paper_matcher, "SURE", 0.5)
    ranges = noisy_scan(test_room, lms200, TRUE)
    x0, y0, _, _ = test_room.bounds
    gave_up = 0
    for guess in (Pose(x0 + 0.3, TRUE.y, TRUE.theta), Pose(TRUE.x, y0 + 0.3, TRUE.theta + 0.1)):
        problem = Problem(test_room, lms200, ranges, guess)
        cost = paper_matcher._Cost(problem, m.config, paper_matcher.scan_turning_function(
            problem.ranges, problem.laser, m.config.shape))
        gave_up += m._search_compiled(problem, cost) is None
        fast = m.localize(problem)
        with monkeypatch.context() as mp:
            step_by_step_tf(mp)
            slow = m.localize(problem)
        assert (fast.pose, fast.evaluations, fast.info) == (slow.pose, slow.evaluations, slow.info)
    assert gave_up > 0
