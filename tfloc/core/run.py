"""A recorded run as one typed value: what ``run.json`` says, read and checked once.

:class:`RunRecord` is what :meth:`tfloc.io.rundir.RunDir.info` returns and what timing, the
report, the verdict, the study steps and the site take: the configuration
(:class:`~tfloc.core.runconfig.RunConfig`, ``None`` for a study of another kind), the study's
kind and its own configuration (a scaling study's), each matcher resolved once
(:class:`RunMatcher`), each dataset with its mode (:class:`RunDataset`), the thresholds, the
environment (versions, :class:`GitState`, :class:`Machine`), the sessions (:class:`Session`),
the fingerprint (what decides the rows: :mod:`tfloc.harness.fingerprint`), the timing pass's
record (:class:`TimingRecord`), the truth-free verdict's (:class:`VerdictRecord`), the
derived tables' (:class:`DerivedRecord`, per producer) and a stepped study's levels. Each
record converts to and from its JSON form (``to_dict``/``from_dict``) in one place; only
:mod:`tfloc.io.rundir` reads and writes the file.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from .modes import SINGLE
from .runconfig import RunConfig
from .thresholds import Thresholds


def _floats(v: Any) -> tuple[float, ...] | None:
    return tuple(float(x) for x in v) if isinstance(v, list | tuple) else None


def _plain(v: Any) -> Any:
    if isinstance(v, tuple):
        return [_plain(x) for x in v]
    if isinstance(v, Mapping):
        return {k: _plain(x) for k, x in v.items()}
    return v


def _to_dict(obj: Any, skip_none: bool = True) -> dict[str, Any]:
    out = {}
    for f in fields(obj):
        v = getattr(obj, f.name)
        if v is None and skip_none:
            continue
        out[f.name] = v.to_dict() if hasattr(v, "to_dict") else _plain(v)
    return out


@dataclass(frozen=True)
class GitState:
    """The checkout a run was made from: its commit and whether its code had uncommitted
    changes (``None`` each where git cannot say)."""

    commit: str | None = None
    dirty: bool | None = None

    @classmethod
    def from_dict(cls, d: Any) -> GitState:
        d = d if isinstance(d, Mapping) else {}
        return cls(d.get("commit"), d.get("dirty"))

    def to_dict(self) -> dict[str, Any]:
        return {"commit": self.commit, "dirty": self.dirty}


@dataclass(frozen=True)
class Machine:
    """The machine a run was made on (``cpu``: the processor's model name)."""

    platform: str = "?"
    processor: str = ""
    cpu: str = "?"
    cpu_count: int | None = None
    python: str = "?"
    node: str = ""

    @classmethod
    def from_dict(cls, d: Any) -> Machine:
        d = d if isinstance(d, Mapping) else {}
        return cls(**{f.name: d[f.name] for f in fields(cls) if f.name in d})

    def to_dict(self) -> dict[str, Any]:
        return _to_dict(self, skip_none=False)


@dataclass(frozen=True)
class Session:
    """One start of a run (or of its timing pass): when it started and ended, the 1/5/15-minute
    load averages then, the tasks and those done before (a run), the cores it was pinned to, its
    CPU and wall seconds, the levels done before (a scaling study), the scans timed, the
    contention probe's figures and the processor's model (a timing pass), the checkout."""

    started: str = ""
    ended: str | None = None
    tasks: int | None = None
    already_done: int | None = None
    loadavg_start: tuple[float, ...] | None = None
    loadavg_end: tuple[float, ...] | None = None
    cores: tuple[int, ...] | None = None
    cpu_s: float | None = None
    wall_s: float | None = None
    levels_done_before: int | None = None
    scans: int | None = None
    contention: Mapping[str, Any] | None = field(default=None, hash=False)
    cpu: str | None = None
    git: GitState | None = None

    @classmethod
    def from_dict(cls, d: Any) -> Session:
        d = d if isinstance(d, Mapping) else {}
        kw: dict[str, Any] = {f.name: d[f.name] for f in fields(cls) if f.name in d}
        for k in ("loadavg_start", "loadavg_end"):
            kw[k] = _floats(d.get(k))
        kw["cores"] = tuple(int(c) for c in d["cores"]) if isinstance(d.get("cores"), list) else None
        kw["git"] = GitState.from_dict(d["git"]) if isinstance(d.get("git"), Mapping) else None
        return cls(**kw)

    def to_dict(self) -> dict[str, Any]:
        return _to_dict(self)


@dataclass(frozen=True)
class TimingRecord:
    """The timing pass's record in ``run.json``: the ``fingerprint`` it was made for, its
    ``sessions`` and whether it is ``complete``."""

    fingerprint: Mapping[str, Any] | None = field(default=None, hash=False)
    sessions: tuple[Session, ...] = field(default=(), hash=False)
    complete: bool = False

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> TimingRecord:
        fp = d.get("fingerprint")
        return cls(fp if isinstance(fp, Mapping) else None,
                   tuple(Session.from_dict(s) for s in d.get("sessions") or ()), bool(d.get("complete")))

    @property
    def last_session(self) -> Session:
        """The pass's last session (an empty one if none)."""
        return self.sessions[-1] if self.sessions else Session()


@dataclass(frozen=True)
class VerdictRecord:
    """The truth-free verdict's record: its rules (the configuration's fields), whether the
    restarts ran, the SHA-256 of the rows it judged and the identity of the code that judged."""

    config: Mapping[str, Any] = field(default_factory=dict, hash=False)
    restarts: bool = True
    rows_sha256: str | None = None
    code: str | None = None

    @classmethod
    def from_dict(cls, d: Any) -> VerdictRecord:
        d = d if isinstance(d, Mapping) else {}
        return cls(dict(d.get("config") or {}), bool(d.get("restarts", True)), d.get("rows_sha256"), d.get("code"))

    def to_dict(self) -> dict[str, Any]:
        return _to_dict(self)


@dataclass(frozen=True)
class DerivedRecord:
    """What tables derived from a run's rows were made from: the identity of the code that
    derived them and the SHA-256 of the rows (and of the verdict) they read."""

    code: str = ""
    rows_sha256: str | None = None
    verdict_sha256: str | None = None

    @classmethod
    def from_dict(cls, d: Any) -> DerivedRecord:
        d = d if isinstance(d, Mapping) else {}
        return cls(str(d.get("code") or ""), d.get("rows_sha256"), d.get("verdict_sha256"))

    def to_dict(self) -> dict[str, Any]:
        return _to_dict(self)


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
        import json

        return json.dumps(dict(self.params), sort_keys=True)


@dataclass(frozen=True)
class RunDataset:
    """One dataset of a run: its ``name``, the directory the run read it from, its ``mode`` (a
    :data:`tfloc.core.modes.MODES` key) and the paper scenarios it declares."""

    name: str
    path: Path
    mode: str = SINGLE.key
    paper_scenarios: tuple[str, ...] = ()


@dataclass(frozen=True)
class RunRecord:
    """A run directory's ``run.json`` (module notes); an empty record when there is none
    (provenance unknown, default thresholds)."""

    config: RunConfig | None = None
    name: str | None = None
    kind: str = "bench"
    study: Mapping[str, Any] = field(default_factory=dict, hash=False)
    matchers: tuple[RunMatcher, ...] = ()
    datasets: tuple[RunDataset, ...] = ()
    thresholds: Thresholds = Thresholds()
    versions: Mapping[str, str | None] = field(default_factory=dict, hash=False)
    git: GitState = GitState()
    machine: Machine = Machine()
    sessions: tuple[Session, ...] = ()
    fingerprint: Mapping[str, Any] | None = field(default=None, hash=False)
    timing: TimingRecord | None = None
    verdict: VerdictRecord | None = None
    derived: Mapping[str, DerivedRecord] = field(default_factory=dict, hash=False)
    levels: tuple[str, ...] = ()
    done: tuple[str, ...] = ()
    command: str | None = None
    exists: bool = False

    @property
    def paths(self) -> dict[str, Path]:
        """Dataset name → directory, as the run recorded them."""
        return {d.name: d.path for d in self.datasets}

    @property
    def labels(self) -> list[str]:
        """The matchers' labels in configuration order."""
        return [m.label for m in self.matchers]

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
