"""A run directory: the one owner of ``run.json`` and of where a run's files are.

``tfloc bench`` writes a run directory, and so does the scaling study (``tfloc scaling``);
``timing``, ``report``, ``export``, ``real-note`` and the guard read it. All of them go through
:class:`RunDir`: it knows the paths (``estimates.csv``, ``run.json``, ``timing.*``, ``report.md``,
``figures/``), reads and checks ``run.json`` once (:meth:`RunDir.info`, a :class:`RunInfo`:
configuration, matchers, datasets, thresholds, the datasets' modes, sessions, fingerprint), and
writes it atomically (a kill leaves the old or the new file, never half of one). A malformed
``run.json`` is one :class:`ResultsError` naming the file and the field.

``run.json`` holds ``config`` (the configuration: ``name``, ``matchers`` as ``{label, name,
params}``, ``success``, …; ``kind`` ``"scaling"`` with the study's own fields under ``scaling``
for a scaling study, absent for a benchmark run), ``versions``, ``git``, ``machine``,
``datasets`` (name → directory; a scaling study's: its tile map), ``sessions`` (one per start:
started, ended, load averages) and ``fingerprint`` (what decides the rows). A study that runs in
steps records ``levels`` and the ones ``done``. ``timing`` is the timing pass's record
(:meth:`RunDir.start_timing`): its ``fingerprint`` (the run's, the pass's parameters), its
``sessions`` and whether it is ``complete``; :meth:`RunDir.discard` removes it with the pass's
files.
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
           "declared": dict, "timing": dict, "verdict": dict, "levels": list, "done": list,
           "config.kind": str, "config.scaling": dict, "timing.sessions": list, "timing.complete": bool,
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
                      for k in ("loadavg_start", "loadavg_end"))
              for v in [*doc.get("sessions", []), *doc.get("timing", {}).get("sessions", [])])
    ok &= all(isinstance(v, str) for v in [*doc.get("levels", []), *doc.get("done", [])])
    ok &= all(isinstance(m, dict) and isinstance(m.get("label"), str) and isinstance(m.get("name"), str)
              and isinstance(m.get("params", {}), dict) for m in doc.get("config", {}).get("matchers", []))
    try:
        thr = Thresholds.from_run(doc)
        ok &= thr.dist_m >= 0 and thr.orient_deg >= 0  # (NaN is not)
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise ResultsError(f"{path}: malformed datasets, sessions, levels, config.matchers or config.success")
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
    def kind(self) -> str:
        """What made the run: ``bench`` (a run configuration), or a study's kind (``scaling``)."""
        return str(self.config.get("kind", "bench"))

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

    @property
    def done(self) -> list[str]:
        """The steps (a scaling study's levels) the run has finished, in order."""
        return list(self.doc.get("done", []))

    @property
    def timing(self) -> dict | None:
        """The timing pass's record (``fingerprint``, ``sessions``, ``complete``), None if none."""
        return self.doc.get("timing")

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
    verdict = property(lambda self: self.path / "verdict.csv", doc="the truth-free verdict per tracker")
    verdict_scans = property(lambda self: self.path / "verdict_scans.csv.gz",
                             doc="the truth-free verdict's per-scan signals and beliefs")
    verdict_checks = property(lambda self: self.path / "verdict_checks.csv",
                              doc="the verdict against the truth, per tracker (recordings with truth)")
    verdict_agreement = property(lambda self: self.path / "verdict_agreement.csv",
                                 doc="the verdict's ranking against the truth's, per recording")
    verdict_flags = property(lambda self: self.path / "verdict_flags.csv",
                             doc="the recordings' flagged stretches the verdict judged across")
    VERDICT_FILES = ("verdict.csv", "verdict_scans.csv.gz", "verdict_checks.csv", "verdict_agreement.csv",
                     "verdict_flags.csv")

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

    def start_session(self, doc: dict[str, Any], n_tasks: int, n_done: int, loadavg: list | None,
                      **extra: Any) -> None:
        """Write ``run.json`` for a new session: ``doc`` (configuration, environment, datasets,
        fingerprint) with the sessions so far plus this one (``n_tasks`` tasks, ``n_done`` of them
        done before, ``extra`` fields, e.g. the cores it is pinned to); the timing pass's record
        is kept (its own fingerprint says whether it is still current)."""
        try:
            old = self.info().doc
        except ResultsError:
            old = {}
        session = {"started": _now(), "tasks": n_tasks, "already_done": n_done, "loadavg_start": loadavg,
                   **extra}
        kept = {"timing": old["timing"]} if "timing" in old and "timing" not in doc else {}
        self.write({**doc, **kept, "sessions": list(old.get("sessions", [])) + [session]})

    def update(self, fields: dict[str, Any], **session: Any) -> None:
        """Replace top-level ``fields`` of ``run.json`` (e.g. the steps ``done``) and update the
        last session with ``session`` (e.g. its CPU seconds so far)."""
        doc = self.info().doc
        doc.update(fields)
        if session and doc.get("sessions"):
            doc["sessions"][-1].update(session)
        self.write(doc)

    def close_session(self, loadavg: list | None, **extra: Any) -> None:
        """Record the end time and load average of the last session (and ``extra`` fields)."""
        try:
            doc = self.info().doc
        except ResultsError:
            return
        if doc.get("sessions"):
            doc["sessions"][-1].update(ended=_now(), loadavg_end=loadavg, **extra)
            self.write(doc)

    def start_timing(self, fingerprint: dict[str, Any], loadavg: list | None, fresh: bool) -> None:
        """Record in ``run.json`` that a timing pass of ``fingerprint`` starts (not complete until
        :meth:`close_timing`): a new session, after the sessions of the same pass unless
        ``fresh`` (another pass: its record starts over)."""
        doc = self.info(required=True).doc
        old = doc.get("timing") or {}
        previous = [] if fresh or old.get("fingerprint") != fingerprint else list(old.get("sessions", []))
        session = {"started": _now(), "loadavg_start": loadavg}
        doc["timing"] = {"fingerprint": fingerprint, "complete": False, "sessions": previous + [session]}
        self.write(doc)

    def close_timing(self, loadavg: list | None, **extra: Any) -> None:
        """Record that the timing pass started last is complete (``timing.csv`` and ``timing.md``
        are written and current), with ``extra`` fields of its session (e.g. its cores)."""
        doc = self.info(required=True).doc
        record = doc.get("timing") or {"sessions": [{}]}
        record["sessions"][-1].update(ended=_now(), loadavg_end=loadavg, **extra)
        doc["timing"] = {**record, "complete": True}
        self.write(doc)

    def discard(self, also: tuple[str, ...] = ()) -> None:
        """Remove the run's results, its timing pass (``timing.csv``, ``timing.md`` and the record
        in ``run.json``), its truth-free verdict, ``run.json`` and the files named ``also``
        (``--regenerate``)."""
        for f in (self.estimates, self.timing_csv, self.timing_md, *(self.path / n for n in self.VERDICT_FILES),
                  *(self.path / n for n in also), self.run_json):
            f.unlink(missing_ok=True)

    def make(self) -> None:
        """Create the directory (a :class:`ResultsError` if it cannot be)."""
        try:
            self.path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ResultsError(f"{self.path}: cannot create the run directory ({exc.strerror or exc})") from None


def _now() -> str:
    """The local time as ``run.json`` records it (ISO 8601 with the offset)."""
    return time.strftime("%Y-%m-%dT%H:%M:%S%z")
