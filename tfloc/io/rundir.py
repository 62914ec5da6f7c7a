"""A run directory: the one owner of ``run.json`` and of where a run's files are.

``tfloc bench`` writes a run directory; ``timing``, ``report``, ``export``, ``real-note`` and the
guard read it. All of them go through :class:`RunDir`: it knows the paths (``estimates.csv``,
``run.json``, ``timing.*``, ``report.md``, ``figures/``), reads and checks ``run.json`` once
(:meth:`RunDir.info`, a :class:`RunInfo`: configuration, matchers, datasets, thresholds, the
datasets' modes, sessions, fingerprint), and writes it atomically (a kill leaves the old or the
new file, never half of one). A malformed ``run.json`` is one :class:`ResultsError` naming the
file and the field.

``run.json`` (written by :mod:`tfloc.harness.runner`) holds ``config`` (the run configuration:
``name``, ``matchers`` as ``{label, name, params}``, ``success``, ``jobs``, …), ``versions``,
``git``, ``machine``, ``datasets`` (name → directory), ``sessions`` (one per start: started,
ended, load averages) and ``fingerprint`` (what decides the rows).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from tfloc.core.thresholds import Thresholds
from tfloc.errors import ResultsError, TflocError

from .atomic import replace_atomically
from .estimates import REQUIRED, read_estimates
from .scenario import SINGLE, read_scenario
from .text import parse_text

RUN_JSON = "run.json"
ESTIMATES = "estimates.csv"

#: the run.json fields a reader relies on, and what each must be
_FIELDS = {"config": dict, "git": dict, "machine": dict, "versions": dict, "datasets": dict, "sessions": list,
           "declared": dict,
           "config.success": dict, "config.matchers": list, "git.commit": (str, type(None)),
           "git.dirty": (bool, type(None)), "config.name": str}


def _finite_list(v: list) -> bool:
    return bool(v) and all(isinstance(x, int | float) and not isinstance(x, bool) and abs(x) < 1e300 for x in v)


def check_run_doc(doc: object, path: Path) -> dict:
    """``doc`` if it is a well-formed ``run.json`` document, else a :class:`ResultsError` naming
    ``path`` and the field at fault."""
    if not isinstance(doc, dict):
        raise ResultsError(f"{path}: expected a JSON object")
    for name, kind in _FIELDS.items():
        *parents, leaf = name.split(".")
        d = doc
        for p in parents:
            d = d.get(p, {})
        if leaf in d and not isinstance(d[leaf], kind):
            raise ResultsError(f"{path}: field {name} is {type(d[leaf]).__name__}, not the expected "
                               f"{getattr(kind, '__name__', 'string or null')}")
    ok = all(isinstance(v, str) for v in doc.get("datasets", {}).values())
    ok &= all(isinstance(v, dict) and isinstance(v.get("started", ""), str)
              and all(isinstance(v.get(k) or [0], list) and _finite_list(v.get(k) or [0])
                      for k in ("loadavg_start", "loadavg_end")) for v in doc.get("sessions", []))
    ok &= all(isinstance(m, dict) and isinstance(m.get("label"), str) and isinstance(m.get("name"), str)
              and isinstance(m.get("params", {}), dict) for m in doc.get("config", {}).get("matchers", []))
    try:
        thr = Thresholds.from_run(doc)
        ok &= thr.dist_m >= 0 and thr.orient_deg >= 0  # (NaN is not)
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise ResultsError(f"{path}: malformed datasets, sessions, config.matchers or config.success")
    return doc


@dataclass(frozen=True)
class RunInfo:
    """What ``run.json`` says about a run (checked). ``doc`` is the whole document (``{}`` when
    the run has no ``run.json``: provenance unknown, default thresholds)."""

    doc: dict = field(default_factory=dict)

    @property
    def config(self) -> dict:
        return self.doc.get("config", {})

    @property
    def name(self) -> str | None:
        return self.config.get("name")

    @property
    def matchers(self) -> list[dict]:
        """The run's matchers in configuration order: ``{label, name, params}``."""
        return list(self.config.get("matchers", []))

    @property
    def datasets(self) -> dict[str, Path]:
        """Dataset name → directory, as the run recorded them."""
        return {k: Path(v) for k, v in self.doc.get("datasets", {}).items()}

    @property
    def thresholds(self) -> Thresholds:
        """The success thresholds the run was made with (defaults if it records none)."""
        return Thresholds.from_run(self.doc)

    @property
    def sessions(self) -> list[dict]:
        return list(self.doc.get("sessions", []))

    @property
    def fingerprint(self) -> dict | None:
        return self.doc.get("fingerprint")

    def declared(self, dataset: str) -> dict:
        """What a dataset of the run declares in its ``scenario.json`` (``mode``,
        ``paper_scenarios``): read from the dataset if it is on disk, else as the run recorded
        it (``run.json``'s ``declared``); ``{}`` if neither knows."""
        path = self.datasets.get(dataset)
        try:
            if path is not None:
                sc = read_scenario(path)
                return {"mode": sc.mode, "paper_scenarios": list(sc.paper_scenarios)}
        except TflocError:
            pass
        return dict(self.doc.get("declared", {}).get(dataset, {}))

    def mode(self, dataset: str) -> str:
        """The mode of a dataset of the run (:data:`tfloc.io.scenario.MODES`; ``single`` when
        nothing says otherwise)."""
        return str(self.declared(dataset).get("mode", SINGLE))

    def paper_scenarios(self) -> dict[str, tuple[str, ...]]:
        """Dataset → the paper scenarios it declares (datasets that declare none left out)."""
        out = {}
        for name in self.datasets:
            got = tuple(self.declared(name).get("paper_scenarios", ()))
            if got:
                out[name] = got
        return out

    def datasets_in(self, names: list[str], mode: str) -> set[str]:
        """Which of ``names`` are datasets of ``mode``."""
        return {n for n in names if self.mode(n) == mode}


@dataclass(frozen=True)
class RunDir:
    """A run directory (the files of one run configuration)."""

    path: Path

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))

    estimates = property(lambda self: self.path / ESTIMATES, doc="the rows: estimates.csv")
    run_json = property(lambda self: self.path / RUN_JSON, doc="run.json")
    timing_csv = property(lambda self: self.path / "timing.csv", doc="the timing pass's rows")
    timing_md = property(lambda self: self.path / "timing.md", doc="the timing pass's summary")
    report = property(lambda self: self.path / "report.md", doc="the report")
    figures = property(lambda self: self.path / "figures", doc="the report's figures")

    def has_rows(self) -> bool:
        """Whether the run has an ``estimates.csv`` with anything in it."""
        return self.estimates.is_file() and self.estimates.stat().st_size > 0

    def require_results(self) -> None:
        """A :class:`ResultsError` unless this is a run directory with results."""
        if not self.estimates.is_file():
            raise ResultsError(f"{self.path}: no {ESTIMATES} (not a run directory? run 'tfloc bench' first)")

    def results(self, required: tuple[str, ...] = REQUIRED) -> pd.DataFrame:
        """The run's rows (:func:`tfloc.io.estimates.read_estimates`); a missing or empty
        ``estimates.csv`` is a :class:`ResultsError`."""
        self.require_results()
        df = read_estimates(self.path, required)
        if df.empty:
            raise ResultsError(f"{self.estimates}: no results yet (no task of the run has finished)")
        return df

    def info(self, required: bool = False) -> RunInfo:
        """``run.json``, read and checked once; without one, an empty :class:`RunInfo` (or, if
        ``required``, a :class:`ResultsError`)."""
        if not self.run_json.is_file():
            if required:
                raise ResultsError(f"{self.path}: needs {RUN_JSON} (run 'tfloc bench' first)")
            return RunInfo()
        doc = parse_text(self.run_json, ResultsError, "run.json file", json.loads, ValueError, "JSON")
        info = RunInfo(check_run_doc(doc, self.run_json))
        if required and (not info.matchers or not info.datasets):
            raise ResultsError(f"{self.run_json}: no 'config.matchers' or 'datasets' (not written by tfloc bench?)")
        return info

    def recorded_fingerprint(self) -> dict | None:
        """The fingerprint ``run.json`` records, or None if there is none or it is unreadable
        (a resume then reports that the run records no fingerprint)."""
        try:
            return self.info().fingerprint
        except ResultsError:
            return None

    def write(self, doc: dict[str, Any]) -> None:
        """Write ``run.json`` atomically (a temporary file, fsynced, renamed)."""
        replace_atomically(self.run_json, lambda fh: fh.write(json.dumps(doc, indent=2) + "\n"))

    def start_session(self, doc: dict[str, Any], n_tasks: int, n_done: int, loadavg: list | None) -> None:
        """Write ``run.json`` for a new session: ``doc`` (configuration, environment, datasets,
        fingerprint) with the sessions so far plus this one."""
        try:
            previous = self.info().sessions
        except ResultsError:
            previous = []
        session = {"started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "tasks": n_tasks,
                   "already_done": n_done, "loadavg_start": loadavg}
        self.write({**doc, "sessions": previous + [session]})

    def close_session(self, loadavg: list | None) -> None:
        """Record the end time and load average of the last session."""
        try:
            doc = self.info().doc
        except ResultsError:
            return
        if doc.get("sessions"):
            doc["sessions"][-1].update(ended=time.strftime("%Y-%m-%dT%H:%M:%S%z"), loadavg_end=loadavg)
            self.write(doc)

    def discard(self) -> None:
        """Remove the run's results and ``run.json`` (``--regenerate``)."""
        self.estimates.unlink(missing_ok=True)
        self.run_json.unlink(missing_ok=True)

    def make(self) -> None:
        """Create the directory (a :class:`ResultsError` if it cannot be)."""
        try:
            self.path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ResultsError(f"{self.path}: cannot create the run directory ({exc.strerror or exc})") from None

