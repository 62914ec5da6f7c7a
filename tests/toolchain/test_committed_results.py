"""Every committed run directory was made by a verb of the package from a clean tree: its
run.json records the code that answered (tfloc's answering source) and no uncommitted change to
it; every report opens with its headline table beside its headline.csv; the names its tables
use are matchers or presets a user can pass to any verb, each for the configuration it labels."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from _paths import RESULTS

from tfloc.core.matcher import factory_of
from tfloc.core.presets import resolve

RUNS = sorted(p.parent for p in RESULTS.rglob("run.json") if "site" not in p.parts)


@pytest.mark.parametrize("run", RUNS, ids=lambda p: p.relative_to(RESULTS).as_posix())
def test_a_committed_run_was_made_from_a_clean_tree_and_names_its_code(run: Path) -> None:
    doc = json.loads((run / "run.json").read_text())
    git = doc.get("git") or {}
    assert git.get("commit") and git.get("dirty") is False, f"{run}: made from {git}"
    code = (doc.get("fingerprint") or {}).get("tfloc")
    assert isinstance(code, dict) and len(code.get("source", "")) == 64, f"{run}: no code identity"


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
