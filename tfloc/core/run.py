"""A recorded run as one value: what ``run.json`` says, read and checked once.

:class:`Run` is what :meth:`tfloc.io.rundir.RunDir.info` returns and what timing, the report, the
verdict, the study steps and the site take: the configuration (:class:`~tfloc.core.runconfig.RunConfig`,
``None`` for a study of another kind or a run.json without one), each matcher resolved once
(:class:`RunMatcher`: label, the name configured, the registered matcher it stands for, the
parameters as configured and as resolved), each dataset with its mode (:class:`RunDataset`), the
thresholds, the sessions, the fingerprint and the timing pass's record (:class:`TimingRecord`).
``doc`` keeps the whole document, for the writer and for provenance.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .modes import SINGLE
from .runconfig import MatcherSpec, RunConfig
from .thresholds import Thresholds


@dataclass(frozen=True)
class RunMatcher:
    """One matcher column of a run: its ``label``, the ``name`` configured (a registered matcher,
    a preset or ``module:Class``), ``base`` the registered matcher it stands for (a preset
    resolved), ``params`` as configured and ``resolved`` with every default (as the fingerprint
    recorded them; ``params`` where it records none)."""

    label: str
    name: str
    base: str
    params: Mapping[str, Any] = field(default_factory=dict, hash=False)
    resolved: Mapping[str, Any] = field(default_factory=dict, hash=False)

    @property
    def params_json(self) -> str:
        """``params`` as the matcher loader takes them (sorted JSON)."""
        return json.dumps(dict(self.params), sort_keys=True)

    def spec(self) -> MatcherSpec:
        """The configuration's entry for this matcher."""
        return MatcherSpec.make(self.name, dict(self.params), self.label)


@dataclass(frozen=True)
class RunDataset:
    """One dataset of a run: its ``name``, the directory the run read it from, its ``mode`` (a
    :data:`tfloc.core.modes.MODES` key) and the paper scenarios it declares."""

    name: str
    path: Path
    mode: str = SINGLE.key
    paper_scenarios: tuple[str, ...] = ()


@dataclass(frozen=True)
class TimingRecord:
    """The timing pass's record in ``run.json``: the ``fingerprint`` it was made for, its
    ``sessions`` (started, ended, load averages, cores) and whether it is ``complete``."""

    fingerprint: Mapping[str, Any] | None = field(default=None, hash=False)
    sessions: tuple[Mapping[str, Any], ...] = field(default=(), hash=False)
    complete: bool = False

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> TimingRecord:
        fp = d.get("fingerprint")
        return cls(fp if isinstance(fp, Mapping) else None, tuple(d.get("sessions") or ()), bool(d.get("complete")))

    def to_dict(self) -> dict[str, Any]:
        return {"fingerprint": self.fingerprint, "complete": self.complete, "sessions": [dict(s) for s in self.sessions]}

    @property
    def last_session(self) -> Mapping[str, Any]:
        """The pass's last session (``{}`` if none)."""
        return self.sessions[-1] if self.sessions else {}


@dataclass(frozen=True)
class Run:
    """A run directory's ``run.json`` (module notes); an empty :class:`Run` when there is none
    (provenance unknown, default thresholds)."""

    doc: Mapping[str, Any] = field(default_factory=dict, hash=False)
    config: RunConfig | None = None
    matchers: tuple[RunMatcher, ...] = ()
    datasets: tuple[RunDataset, ...] = ()
    thresholds: Thresholds = Thresholds()
    timing: TimingRecord | None = None

    @property
    def config_doc(self) -> Mapping[str, Any]:
        """``run.json``'s ``config`` as written (a scaling study's fields under ``scaling``)."""
        return self.doc.get("config", {})

    @property
    def name(self) -> str | None:
        return self.config_doc.get("name")

    @property
    def kind(self) -> str:
        """What made the run: ``bench`` (a run configuration), or a study's kind (``scaling``)."""
        return str(self.config_doc.get("kind", "bench"))

    @property
    def paths(self) -> dict[str, Path]:
        """Dataset name → directory, as the run recorded them."""
        return {d.name: d.path for d in self.datasets}

    @property
    def labels(self) -> list[str]:
        """The matchers' labels in configuration order."""
        return [m.label for m in self.matchers]

    def matcher(self, label: str) -> RunMatcher | None:
        return next((m for m in self.matchers if m.label == label), None)

    @property
    def sessions(self) -> list[Mapping[str, Any]]:
        return list(self.doc.get("sessions", []))

    @property
    def fingerprint(self) -> Mapping[str, Any] | None:
        return self.doc.get("fingerprint")

    @property
    def git(self) -> Mapping[str, Any]:
        return self.doc.get("git", {})

    @property
    def done(self) -> list[str]:
        """The steps (a scaling study's levels) the run has finished, in order."""
        return list(self.doc.get("done", []))

    def dataset(self, name: str) -> RunDataset | None:
        return next((d for d in self.datasets if d.name == name), None)

    def mode(self, dataset: str) -> str:
        """The mode key of a dataset of the run (``single`` when nothing says otherwise)."""
        d = self.dataset(dataset)
        return d.mode if d is not None else SINGLE.key

    def datasets_in(self, names: list[str], mode: str) -> set[str]:
        """Which of ``names`` are datasets of ``mode`` (a mode key)."""
        return {n for n in names if self.mode(n) == mode}

    def paper_scenarios(self) -> dict[str, tuple[str, ...]]:
        """Dataset → the paper scenarios it declares (datasets that declare none left out)."""
        return {d.name: d.paper_scenarios for d in self.datasets if d.paper_scenarios}
