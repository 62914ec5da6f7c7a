"""Bad matcher parameters are refused when the matcher is built, never met later as a crash.

For every registered matcher and every parameter (nested ones included): a value of the wrong
type, NaN, zero, a negative number, an empty or negative list either raises ParameterError (a
TflocError naming the parameter) at construction, or the matcher so built localizes a scan
without raising and within a time limit. ``make test`` tries a deterministic sample; ``make
fuzz`` (TFLOC_FUZZ_EXAMPLES ≥ 1000) tries them all.
"""

from __future__ import annotations

import dataclasses
import math

import pytest
from _fuzz import Tally, finish, judge

import tfloc
from tfloc.core.matcher import available_matchers, get_matcher
from tfloc.core.params import check_params
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate
from tfloc.errors import ParameterError


def _buildable(name: str) -> bool:
    try:
        get_matcher(name)
        return True
    except tfloc.MatcherError:
        return False


#: an external program (a batch tracker: ``run_batch``, no in-process step) is left out: its
#: values go to the program's own configuration file (tests/baselines/test_mrpt_pf.py)
MATCHERS = [m for m in available_matchers() if _buildable(m)
            and not callable(getattr(get_matcher(m), "run_batch", None))]


def fields(config, prefix: str = "") -> list[tuple[str, object]]:
    """(dotted name, default value) of every parameter, nested configurations flattened."""
    out = []
    for f in dataclasses.fields(config):
        v = getattr(config, f.name)
        if dataclasses.is_dataclass(v):
            out += fields(v, f"{prefix}{f.name}.")
        else:
            out.append((prefix + f.name, v))
    return out


def nest(name: str, value) -> dict:
    """``a.b`` = v → ``{"a": {"b": v}}`` (how a run configuration overrides a nested parameter)."""
    head, _, rest = name.partition(".")
    return {head: nest(rest, value) if rest else value}


def bad_values(default) -> list:
    if isinstance(default, bool):
        return ["yes", 1]
    if isinstance(default, int | float):
        return [0, -1, -0.25, math.nan, "1", None, True]
    if isinstance(default, tuple):
        return [[], [0], [-1.0], "x", [math.inf]]
    if isinstance(default, str):
        return [3, "no-such-choice"]
    return [object()]


CASES = [(m, name, v) for m in MATCHERS for name, d in fields(get_matcher(m).config) for v in bad_values(d)]


@pytest.fixture(scope="module")
def problem(test_room, lms200) -> tfloc.Problem:
    true = Pose(3.0, 3.5, 0.3)
    return tfloc.Problem(test_room, lms200, test_room.raycast(true, lms200), Pose(3.15, 3.4, 0.33))


def test_every_matcher_has_a_config_with_defaults_that_pass_its_rules() -> None:
    for m in MATCHERS:
        cfg = get_matcher(m).config
        assert dataclasses.is_dataclass(cfg)
        check_params(cfg)


def test_every_rule_names_a_parameter() -> None:
    for m in MATCHERS:
        configs = [get_matcher(m).config]
        configs += [v for c in configs for v in vars(c).values() if dataclasses.is_dataclass(v)]
        for c in configs:
            names = {f.name for f in dataclasses.fields(c)}
            for rule, params in getattr(type(c), "RULES", {}).items():
                assert set(params) <= names, (m, rule, set(params) - names)


@pytest.mark.parametrize("matcher, key, value, message", [
    ("csm-corr", "search_radiuss", 2.0, r"unknown parameter\(s\) search_radiuss; known: block, "),
    ("csm-corr", "resolution", -0.02, r"resolution must be > 0, got -0.02"),
    ("tf", "spacing", 0.0, r"spacing must be > 0"),
    ("tf-best", "window", None, r"window must be an integer, got None"),
    ("tf-plus", "select", "best", r"select must be one of 'residual', 'virtual', 'tf'"),
    ("tf-plus", "refinement", {"iterations": -1}, r"refinement.iterations must be >= 1"),
    ("o3d-icp", "gates", [1.0, -0.5], r"gates must be all > 0"),
    ("kiss-icp", "voxel_sizes", [], r"voxel_sizes must be a non-empty list"),
    ("cv-corners", "inlier_tol", "0.2", r"inlier_tol must be a finite number, got '0.2'"),
])
def test_bad_parameters_are_named(matcher, key, value, message) -> None:
    if matcher not in MATCHERS:
        pytest.skip(f"{matcher} is not installed")
    with pytest.raises(ParameterError, match=rf"matcher '{matcher}': {message}") as err:
        get_matcher(matcher, **{key: value})
    assert err.value.names and err.value.names[0].split(".")[0] == key


def test_bad_parameter_values_are_refused_at_construction(problem, tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)  # a relative cache_dir ("no-such-choice") is created here
    tally = Tally("matcher parameters")

    def run(m) -> Estimate:
        if hasattr(m, "localize"):
            return m.localize(problem)
        m.start(problem.map, problem.laser, problem.initial)  # a tracker: one scan from the guess
        return m.step(problem.ranges, Pose(0.0, 0.0, 0.0), 0.0)

    for matcher in MATCHERS:  # compiled and warm before the time limit counts (a fresh clone compiles)
        run(get_matcher(matcher))
    for matcher, name, value in CASES:
        def build_and_localize(matcher=matcher, name=name, value=value):
            try:
                m = get_matcher(matcher, **nest(name, value))
            except ParameterError:
                return
            if hasattr(m, "localize"):
                est = m.localize(problem)
            else:  # a tracker (no single-scan mode): started at the guess, one scan
                m.start(problem.map, problem.laser, problem.initial)
                est = m.step(problem.ranges, Pose(0.0, 0.0, 0.0), 0.0)
            assert isinstance(est, Estimate)

        judge(tally, [f"{matcher} {name}={value!r}"], build_and_localize, [name.split(".")[0]])
    finish(tally)
