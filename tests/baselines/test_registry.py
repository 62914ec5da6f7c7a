"""Baselines in the registry: a missing optional library gives a clear message, others still run."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from _paths import ROOT
from _registry import BASELINES, kind, single_scan
from tfloc.baselines._geometry import matrix_to_pose, pose_to_matrix
from tfloc.baselines.o3d_icp import Config as O3dConfig

from tfloc import Pose
from tfloc.core.params import resolve_params
from tfloc.errors import ParameterError

_SCRIPT = """
import json, sys
sys.modules[{module!r}] = None  # simulate the library being absent
sys.path.insert(0, {tests!r})
import tfloc
from _baseline_cases import make_problem
out = {{}}
try:
    tfloc.get_matcher({name!r})
    out["missing"] = None
except tfloc.MatcherError as exc:
    out["missing"] = str(exc)
problem, true = make_problem()
est = tfloc.get_matcher({other!r}).localize(problem)
out["other_error_m"] = est.pose.distance_to(true)
print(json.dumps(out))
"""


@pytest.mark.parametrize(("name", "module", "other"), [
    ("kiss-icp", "kiss_icp", "csm-corr"),
    ("o3d-icp", "open3d", "kiss-icp"),
    ("cv-corners", "cv2", "o3d-icp"),
    ("gicp", "small_gicp", "csm-corr"),
    ("karto", "karto_scanmatcher", "o3d-icp"),   # as on Python ≥ 3.12, where it has no wheel
    ("amcl-wheel", "amcl", "csm-corr"),          # an optional extra (GPL-3.0)
])
def test_missing_library_is_a_clear_matcher_error(name: str, module: str, other: str) -> None:
    code = _SCRIPT.format(module=module, tests=str(ROOT / "tests"), name=name, other=other)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=120)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["missing"] is not None
    assert repr(name) in out["missing"] and module in out["missing"] and "not installed" in out["missing"]
    assert out["other_error_m"] < 0.02
    if name == "karto":  # the one line says why
        assert "tfloc[karto]" in out["missing"] and "Python 3.8-3.11 only" in out["missing"]
        assert "\n" not in out["missing"]
    if name == "amcl-wheel":
        assert "tfloc[amcl]" in out["missing"] and "\n" not in out["missing"]


def test_se2_round_trip_and_projection() -> None:
    pose = Pose(1.5, -2.0, 2.9)
    for dim in (3, 4):
        back = matrix_to_pose(pose_to_matrix(pose, dim))
        assert np.allclose(back.as_array(), pose.as_array())
    t = pose_to_matrix(pose, 4)
    t[:3, :3] = t[:3, :3] @ np.array([[1, 0, 0], [0, math.cos(0.01), -math.sin(0.01)], [0, math.sin(0.01), math.cos(0.01)]])
    t[2, 3] = 0.3
    assert abs(matrix_to_pose(t).theta - 2.9) < 1e-3


def test_resolve_params_rejects_unknown_and_tuples_lists() -> None:
    cfg = resolve_params(O3dConfig, None, {"gates": [0.5, 0.1]})
    assert cfg.gates == (0.5, 0.1)
    with pytest.raises(ParameterError, match="bogus"):
        resolve_params(O3dConfig, None, {"bogus": 1})


class _ProtocolOnlyMap:
    """A map that offers only the Map protocol (no ``segments``), as a GridMap would."""

    def __init__(self, inner: object) -> None:
        self._inner = inner

    def raycast(self, poses, laser):  # noqa: ANN001, ANN201
        return self._inner.raycast(poses, laser)

    def is_free(self, xy, clearance=0.0):  # noqa: ANN001, ANN201
        return self._inner.is_free(xy, clearance)

    def in_bounds(self, xy):  # noqa: ANN001, ANN201
        return self._inner.in_bounds(xy)

    def sample_points(self, spacing):  # noqa: ANN001, ANN201
        return self._inner.sample_points(spacing)

    @property
    def bounds(self):  # noqa: ANN201
        return self._inner.bounds


@pytest.mark.parametrize("name", BASELINES)
def test_uses_only_the_map_protocol(name: str) -> None:
    from _baseline_cases import make_problem

    import tfloc
    matcher = single_scan(name)
    problem, true = make_problem()
    wrapped = tfloc.Problem(_ProtocolOnlyMap(problem.map), problem.laser, problem.ranges,
                            None if kind(matcher) == "global" else problem.initial)
    est = matcher.localize(wrapped)
    assert est.pose.distance_to(true) < 0.02


@pytest.mark.parametrize("name", BASELINES)
@pytest.mark.parametrize("n_returns", [1, 3])
def test_tiny_scans_do_not_crash(name: str, n_returns: int) -> None:
    from _baseline_cases import make_problem

    import tfloc
    matcher = single_scan(name)
    problem, _ = make_problem()
    ranges = np.full_like(problem.ranges, np.inf)
    ranges[80:80 + n_returns] = problem.ranges[80:80 + n_returns]
    tiny = tfloc.Problem(problem.map, problem.laser, ranges, problem.initial)
    est = matcher.localize(tiny)
    assert est.pose.is_finite()
    assert np.isfinite(matcher.score(tiny, est.pose))


def test_missing_matcher_module_is_not_blamed_on_a_library(monkeypatch: pytest.MonkeyPatch) -> None:
    import tfloc.core.matcher as registry

    monkeypatch.setitem(registry._registry(), "ghost", "tfloc.baselines.no_such_module:Ghost")
    with pytest.raises(registry.MatcherError, match="its module 'tfloc.baselines.no_such_module' is not part"):
        registry.get_matcher("ghost")


_RUN = """
import sys
sys.modules["karto_scanmatcher"] = None  # as on Python >= 3.12, where it has no wheel
from pathlib import Path
from tfloc.harness.config import MatcherSpec, RunConfig
from tfloc.harness.runner import run
from tfloc.io.estimates import read_estimates
cfg = RunConfig("t", Path({out!r}), (Path({data!r}),), (MatcherSpec.make("karto"), MatcherSpec.make("csm-corr")),
                jobs=1, limit_per_group=1)
print(sorted(set(read_estimates(run(cfg, progress=False)).matcher)))
"""


def test_a_run_leaves_out_a_matcher_whose_library_is_missing(tmp_path: Path) -> None:
    """karto without its library (Python ≥ 3.12): one line says why, every other matcher runs."""
    code = _RUN.format(out=str(tmp_path / "run"), data=str(ROOT / "data" / "scenarios" / "detail-1"))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "['csm-corr']"
    left_out = [line for line in proc.stderr.splitlines() if "left out" in line]
    assert len(left_out) == 1 and "karto" in left_out[0] and "Python 3.8-3.11 only" in left_out[0]
