"""The accuracy regression guard: rerun the fixed-seed subset and compare with the reference.

Fails with a readable table of every metric that got worse than its tolerance allows (see
tfloc/evaluation/guard.py for the tolerances and why). Update the reference deliberately with
`tfloc guard --update`.
"""

from __future__ import annotations

import os

import pytest
from _paths import ROOT

from tfloc.cli import guard as verb
from tfloc.cli.guard import run_subset
from tfloc.evaluation import guard
from tfloc.harness.config import load_config
from tfloc.io.table import read_frame
from tfloc.io.tables import GUARD, GUARD_TRACKING


@pytest.fixture(scope="module")
def config(tmp_path_factory):
    os.chdir(ROOT)  # the run configuration's paths are relative to the project root
    cfg = load_config(ROOT / verb.CONFIG)
    return cfg.with_overrides(out=tmp_path_factory.mktemp("guard") / "run")


@pytest.fixture(scope="module")
def reference():
    return read_frame(ROOT / verb.REFERENCE, GUARD)


def test_reference_covers_every_guarded_matcher(config, reference):
    assert {m.label for m in config.matchers} <= set(reference.matcher)
    assert set(reference.group) == {f"d{i}-a{j}" for i in (1, 2, 3) for j in (1, 2, 3)} | {"all"}
    assert (reference[reference.group != "all"].n == config.limit_per_group).all()


def test_no_accuracy_regression(config, reference):
    current = run_subset(config, progress=False)
    diff = guard.compare(current, reference)
    assert len(diff) == len(reference) * len(guard.RULES)
    assert not diff.worse.any(), "accuracy regression:\n" + guard.format_table(diff)


def test_no_tracking_regression(tmp_path_factory):
    """The tracking guard: seq-quick's tracked share, APE RMSE and unrecovered losses per matcher."""
    os.chdir(ROOT)
    cfg = load_config(ROOT / verb.TRACKING_CONFIG)
    cfg = cfg.with_overrides(out=tmp_path_factory.mktemp("guard-tracking") / "run")
    reference = read_frame(ROOT / verb.TRACKING_REFERENCE, GUARD_TRACKING)
    assert {m.label for m in cfg.matchers} <= set(reference.matcher)
    current = run_subset(cfg, progress=False, summarise=guard.tracking_summary)
    diff = guard.compare(current, reference, guard.TRACK_RULES)
    assert len(diff) == len(reference) * len(guard.TRACK_RULES)
    assert not diff.worse.any(), "tracking regression:\n" + guard.format_table(diff)
    worse = reference.assign(tracked_pct=reference.tracked_pct + 2.0)  # a reference 2 scans better
    assert guard.compare(current, worse, guard.TRACK_RULES).worse.any()  # the guard bites
