"""``tf-plus``'s one-call pipeline (:mod:`tfloc.tfplus.pipeline`) gives the staged path's answers
bit for bit, on vector and grid maps, simulated and real; the configurations and maps it does not
cover go the staged way."""

from __future__ import annotations

import numpy as np
import pytest
from _paths import ROOT
from _tf_cases import TRUE, few_returns_problem, noisy_scan
from _tfplus_oracles import step_by_step_tfplus
from shapely.geometry import box

from tfloc import Pose, Problem, VectorMap
from tfloc.harness.workspace import problem_of
from tfloc.io.scenario import load_dataset
from tfloc.maps.build import rasterize
from tfloc.tfplus import pipeline
from tfloc.tfplus.matcher import TurningFunctionPlusMatcher


def _both(matcher: TurningFunctionPlusMatcher, problem: Problem,
          monkeypatch: pytest.MonkeyPatch) -> tuple:
    """The answer of the pipeline and of the staged path (the pipeline switched off)."""
    fused = matcher.localize(problem)
    with monkeypatch.context() as mp:
        mp.setattr(pipeline, "plan_for", lambda *a, **k: None)
        staged = matcher.localize(problem)
    return fused, staged


def _same(a, b) -> bool:
    return (a.pose.as_array().tobytes() == b.pose.as_array().tobytes() and a.info == b.info
            and a.evaluations == b.evaluations and a.converged == b.converged)


def _guesses(rng: np.random.Generator, n: int) -> list[Pose]:
    return [Pose(TRUE.x + rng.uniform(-1.5, 1.5), TRUE.y + rng.uniform(-1.0, 1.0),
                 TRUE.theta + rng.uniform(-0.25, 0.25)) for _ in range(n)]


CHANGED = {"free_distance": 0.05, "short_residual": 0.05, "see_through_share": 0.05, "short_refine": True,
           "object_extent": 1.2}


@pytest.mark.parametrize("overrides", [{}, {"beam_check": False}, {"tf_seed": False},
                                       {"refinement": {"prune_after": 0}},
                                       {"refinement": {"iterations": 3, "prune_after": 3, "keep": 1}},
                                       {"coarse_points": 0, "candidates": 2},
                                       {"refine_to": "field"}, CHANGED,
                                       {**CHANGED, "refine_to": "field", "beam_check": False},
                                       {"short_residual": 0.0, "see_through_share": 0.0, "short_margin": 0.1}])
def test_pipeline_equals_the_stages_on_a_vector_map(overrides, test_room, lms200, monkeypatch):
    m = TurningFunctionPlusMatcher(**overrides)
    rng = np.random.default_rng(7)
    for seed, guess in enumerate(_guesses(rng, 6)):
        p = Problem(test_room, lms200, noisy_scan(test_room, lms200, TRUE, seed), guess)
        if seed == 0:
            m.prepare(p)
        assert pipeline.plan_for(p, m.config) is not None
        fused, staged = _both(m, p, monkeypatch)
        assert _same(fused, staged), (overrides, seed)


@pytest.mark.parametrize("overrides", [{}, {"refinement": {"faces": False}}, {"tf_seed": False},
                                       {"refinement": {"prune_after": 0}}, CHANGED,
                                       {**CHANGED, "beam_check": False}])
def test_pipeline_equals_the_stages_on_a_grid_map(overrides, test_room, lms200, monkeypatch):
    grid = rasterize(test_room, 0.05)
    m = TurningFunctionPlusMatcher(**overrides)
    rng = np.random.default_rng(8)
    for seed, guess in enumerate(_guesses(rng, 5)):
        p = Problem(grid, lms200, noisy_scan(test_room, lms200, TRUE, seed), guess)
        assert pipeline.plan_for(p, m.config) is not None
        fused, staged = _both(m, p, monkeypatch)
        assert _same(fused, staged), (overrides, seed)


@pytest.mark.parametrize(("name", "overrides"), [
    ("office-pool", {}), ("real-intel-scan-to-map", {}), ("real-csail-scan-to-map", {}),
    ("changed-clutter-25", {**CHANGED, "refine_to": "field"}),
    ("real-intel-scan-to-map", CHANGED),
    ("real-csail-scan-to-map", {"tf_seed": False, "search_radius": 0.3, "heading_span": 0.16,
                                "candidates": 1})])
def test_pipeline_equals_the_stages_on_bundled_scans(name, overrides, monkeypatch):
    scenario, scans = load_dataset(str(ROOT / "data" / "scenarios" / name))
    items = list(scans.values())
    m = TurningFunctionPlusMatcher(**overrides)
    m.prepare(problem_of(scenario, items[0]))
    for scan in items[::max(1, len(items) // 8)][:8]:
        p = problem_of(scenario, scan)
        assert pipeline.plan_for(p, m.config) is not None
        fused, staged = _both(m, p, monkeypatch)
        assert _same(fused, staged), (name, scan.scan_id)


def test_too_few_returns_is_the_same_no_answer(lms200, monkeypatch):
    p = few_returns_problem(lms200, 2)
    m = TurningFunctionPlusMatcher()
    m.prepare(p)
    assert pipeline.plan_for(p, m.config) is not None
    fused, staged = _both(m, p, monkeypatch)
    assert fused == staged and fused.info["status"] == "no-answer" and "2 returns" in fused.info["reason"]


@pytest.mark.parametrize("overrides", [{"heading_sweep": False},
                                       {"grid": False}, {"refine": False}, {"select": "tf"},
                                       {"select": "virtual"}])
def test_other_configurations_go_the_staged_way(overrides, test_room, lms200):
    p = Problem(test_room, lms200, noisy_scan(test_room, lms200, TRUE), TRUE)
    m = TurningFunctionPlusMatcher(**overrides)
    m.prepare(p)
    assert pipeline.plan_for(p, m.config) is None
    assert m.localize(p).converged


def test_grid_refined_against_virtual_scans_goes_the_staged_way(test_room, lms200):
    p = Problem(rasterize(test_room, 0.05), lms200, noisy_scan(test_room, lms200, TRUE), TRUE)
    assert pipeline.plan_for(p, TurningFunctionPlusMatcher(refine_to="virtual").config) is None


def test_a_map_without_its_compiled_free_tests_goes_the_staged_way(lms200):
    room = VectorMap(outline=box(0, 0, 6, 4), obstacles=(box(2.0, 1.4, 2.4, 1.8),))
    p = Problem(room, lms200, room.raycast(Pose(3.0, 2.5, 0.3), lms200), Pose(3.2, 2.4, 0.35))
    m = TurningFunctionPlusMatcher()
    assert pipeline.plan_for(p, m.config) is None          # not prepared: rings not built
    m.prepare(p)
    assert pipeline.plan_for(p, m.config) is not None


def test_switching_the_compiled_paths_off_switches_the_pipeline_off(test_room, lms200, monkeypatch):
    p = Problem(test_room, lms200, noisy_scan(test_room, lms200, TRUE), TRUE)
    m = TurningFunctionPlusMatcher()
    m.prepare(p)
    assert pipeline.plan_for(p, m.config) is not None      # (and now remembered)
    step_by_step_tfplus(monkeypatch)
    assert pipeline.plan_for(p, m.config) is None


def test_an_undecided_lattice_falls_back_to_the_stages(test_room, lms200, monkeypatch):
    p = Problem(test_room, lms200, noisy_scan(test_room, lms200, TRUE), Pose(3.2, 3.3, 0.45))
    m = TurningFunctionPlusMatcher()
    m.prepare(p)
    expect = m.localize(p)
    calls = []

    def undecided(*args):
        calls.append(args)
        return pipeline.UNDECIDED, 180, np.empty((0, 3)), np.empty(0), np.empty(0), False, 0

    monkeypatch.setattr(pipeline, "run", undecided)
    got = m.localize(p)
    assert calls and _same(got, expect)


def test_the_memo_follows_the_map_and_the_configuration(test_room, lms200):
    grid = rasterize(test_room, 0.05)
    a, b = TurningFunctionPlusMatcher(), TurningFunctionPlusMatcher(beam_check=False)
    pv = Problem(test_room, lms200, noisy_scan(test_room, lms200, TRUE), TRUE)
    pg = Problem(grid, lms200, noisy_scan(test_room, lms200, TRUE), TRUE)
    a.prepare(pv)
    plans = [pipeline.plan_for(q, m.config) for q, m in ((pv, a), (pg, a), (pv, b), (pv, a))]
    assert [p.kind for p in plans] == ["vector", "grid", "vector", "vector"]
    c = TurningFunctionPlusMatcher(refine_to="field")
    assert pipeline.plan_for(pv, c.config).kind == "vector-field"
    assert plans[0] is plans[3] and plans[0] is not plans[2]
    assert plans[0].args[9] is True and plans[2].args[9] is False     # beam_check
