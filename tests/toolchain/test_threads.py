"""One thread per matcher in a worker: every library's thread limit is 1, and a busy matcher's
CPU time (all threads of the process) does not exceed its wall time."""

from __future__ import annotations

import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor

import pytest
from _paths import ROOT
from _registry import NAMES

from tfloc.harness.runner import _init_worker

MATCHERS = tuple(NAMES)  # every registered matcher


def _probe(min_cpu_s: float = 0.3) -> tuple[dict, dict]:
    """In a worker: every matcher on a test-room scan, repeated until it has used ``min_cpu_s`` of
    CPU; returns the thread settings and per matcher (CPU s, wall s) of the repeated calls."""
    import numba

    from tfloc import LaserSpec, Pose, Problem, get_matcher, load_map
    from tfloc.errors import MatcherError
    from tfloc.harness.threads import thread_settings
    from tfloc.harness.workspace import warm

    assert numba.njit(lambda x: x + 1)(1) == 2  # compiling after the limits were set still works
    room = load_map(ROOT / "data" / "maps" / "test-room.geojson")
    laser = LaserSpec.lms200()
    true = Pose(3.0, 3.5, 0.3)
    problem = Problem(room, laser, room.raycast(true, laser), Pose(3.6, 3.1, 0.45))
    times: dict[str, tuple[float, float] | str] = {}  # name → (CPU s, wall s), or why it was not timed
    for name in MATCHERS:
        try:
            m = get_matcher(name)
        except MatcherError:  # an optional library that is not installed (karto on Python ≥ 3.12)
            times[name] = "its optional library is not installed"
            continue
        if not callable(getattr(m, "localize", None)):
            times[name] = "a tracker: no single-scan call to time"
            continue
        prob = Problem(room, laser, problem.ranges, None) if getattr(m, "solves_global", False) else problem
        warm(m, prob)
        c0, w0 = time.process_time(), time.perf_counter()
        while time.process_time() - c0 < min_cpu_s:
            m.localize(prob)
        times[name] = (time.process_time() - c0, time.perf_counter() - w0)
    return thread_settings(), times


@pytest.fixture(scope="module")
def probe():
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(1, mp_context=ctx, initializer=_init_worker) as pool:
        return pool.submit(_probe).result(timeout=600)


def test_every_library_runs_one_thread_in_a_worker(probe):
    settings, _ = probe
    assert {"cv2", "numba", "open3d"} <= set(settings)  # open3d was imported by o3d-icp
    assert settings == {k: 1 for k in settings}, settings


@pytest.mark.parametrize("name", MATCHERS)
def test_cpu_time_of_a_busy_matcher_is_not_more_than_its_wall_time(probe, name):
    timed = probe[1][name]
    if isinstance(timed, str):
        pytest.skip(f"{name}: {timed}")
    cpu, wall = timed
    # One thread cannot use more CPU than wall time; two busy threads would give cpu ≈ 2 × wall.
    assert cpu <= 1.1 * wall + 0.01, (name, cpu, wall)


def test_kiss_icp_and_small_gicp_are_configured_with_one_thread():
    from tfloc.baselines.kiss_icp import KissIcpMatcher

    assert KissIcpMatcher().config.max_num_threads == 1
    gicp = pytest.importorskip("tfloc.baselines.gicp")
    assert gicp.GicpMatcher().config.num_threads == 1
