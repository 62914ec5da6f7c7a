"""Every committed run directory was made by a verb of the package from a clean tree: its
run.json records, per matcher, the code that made its rows, and that code is this checkout's; its
derived tables (headline, summary, tracking, …) and its report record the code that derived them
from its rows, also this checkout's; every report opens with its headline table beside its
headline.csv; the names its tables use are matchers or presets a user can pass to any verb, each
for the configuration it labels."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from _paths import RESULTS, ROOT

from tfloc.cli.report import REPORT, REPORT_CODE
from tfloc.core.matcher import factory_of
from tfloc.core.presets import resolve
from tfloc.harness.derive import PRODUCER as TABLES
from tfloc.harness.derive import stale
from tfloc.harness.identity import ROW_CODE, derived_code, matcher_code
from tfloc.harness.scaling_matchers import ROW_CODE as SCALING_ROW_CODE
from tfloc.io.rundir import RunDir

RUNS = sorted(p.parent for p in RESULTS.rglob("run.json") if "site" not in p.parts)


@pytest.mark.parametrize("run", RUNS, ids=lambda p: p.relative_to(RESULTS).as_posix())
def test_a_committed_run_was_made_from_a_clean_tree_by_this_checkouts_code(run: Path) -> None:
    """Each matcher's rows by the code that decides them (its import closure with the harness's
    row code) as it is in this checkout: an edit a matcher does not import leaves it so."""
    info = RunDir(run).info(required=True)
    assert info.git.commit and info.git.dirty is False, f"{run}: made from {info.git}"
    matchers = (info.fingerprint or {}).get("matchers") or {}
    assert matchers and all(len(m.get("source", "")) == 64 for m in matchers.values()), \
        f"{run}: no code identity per matcher"
    row_code = SCALING_ROW_CODE if info.kind == "scaling" else ROW_CODE
    stale = [label for label, m in matchers.items()
             if matcher_code(factory_of(m["name"]), row_code)["source"] != m["source"]]
    assert not stale, f"{run}: rows of {', '.join(stale)} were made by other code than this checkout's"


DERIVED = [r for r in RUNS if RunDir(r).info().kind == "bench" and (r / "headline.csv").is_file()]


@pytest.mark.parametrize("run", DERIVED, ids=lambda p: p.relative_to(RESULTS).as_posix())
def test_a_committed_runs_tables_were_derived_by_this_checkouts_code(run: Path) -> None:
    """The tables were derived from the rows the run holds (where they are committed) by this
    checkout's deriving code, and its report drawn by this checkout's drawing code."""
    rd = RunDir(run)
    derived = rd.info().derived
    assert TABLES in derived and derived[TABLES].code == derived_code("tfloc.harness.derive"), \
        f"{run}: its tables were derived by other code (tfloc report {run.relative_to(ROOT)})"
    assert not stale(run), f"{run}: {stale(run)}"
    if (run / "report.md").is_file():
        assert derived.get(REPORT) is not None and derived[REPORT].code == derived_code(*REPORT_CODE), \
            f"{run}/report.md drawn by other code (tfloc report {run.relative_to(ROOT)})"


REPORTS = [r for r in RUNS if (r / "report.md").is_file()]


@pytest.mark.parametrize("run", REPORTS, ids=lambda p: p.relative_to(RESULTS).as_posix())
def test_a_committed_report_opens_with_its_headline(run: Path) -> None:
    lines = (run / "report.md").read_text().splitlines()
    first_table = next(i for i, ln in enumerate(lines) if ln.startswith("|"))
    sections = [ln for ln in lines[:first_table] if ln.startswith("## ")]
    assert sections == ["## Headline"], f"{run}/report.md: sections before its first table: {sections}"
    assert (run / "headline.csv").is_file()


def test_every_name_a_headline_uses_is_a_matcher_or_preset() -> None:
    names = set()
    for run in REPORTS:
        with (run / "headline.csv").open() as fh:
            names |= {row["matcher"] for row in csv.DictReader(fh)}
    bad = []
    for name in sorted(names):
        try:
            factory_of(name)
        except Exception as exc:  # noqa: BLE001 - every failure is listed
            bad.append(f"{name}: {exc}")
    assert not bad, "names no verb accepts:\n" + "\n".join(bad)


def test_every_label_a_committed_run_used_names_its_configuration() -> None:
    wrong = []
    for run in RUNS:
        for m in json.loads((run / "run.json").read_text())["config"].get("matchers", []):
            if not isinstance(m, dict):
                continue
            try:
                named = resolve(m["label"], {})
            except Exception as exc:  # noqa: BLE001 - every failure is listed
                named = (str(exc), {})
            if named != resolve(m["name"], m.get("params") or {}):
                wrong.append(f"{run.relative_to(RESULTS)}: {m['label']!r} reads as {named}")
    assert not wrong, "labels a user cannot pass for what they ran:\n" + "\n".join(wrong)
