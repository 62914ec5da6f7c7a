"""A run directory as one typed store: the one owner of ``run.json``, of every table file and of
where a run's files are.

``tfloc bench`` writes a run directory, and so does the scaling study (``tfloc scaling``); every
verb and the site read it, all through :class:`RunDir`: it knows the paths (``estimates.csv``,
``run.json``, each table of :mod:`tfloc.io.tables`, ``timing.md``, ``report.md``,
``figures/``), reads and writes each table through the one codec (:meth:`RunDir.read`,
:meth:`RunDir.frame`, :meth:`RunDir.write`; the rows: :meth:`RunDir.results`), reads and checks
``run.json`` once (:meth:`RunDir.info`, a typed :class:`~tfloc.core.run.RunRecord`), and writes
it atomically (a kill leaves the old or the new file, never half of one). A malformed
``run.json`` is one :class:`ResultsError` naming the file and the field.

``run.json`` holds ``config`` (the configuration: ``name``, ``matchers`` as ``{label, name,
params}``, ``success``, …; ``kind`` ``"scaling"`` with the study's own fields under ``scaling``
for a scaling study, absent for a benchmark run), ``versions``, ``git``, ``machine``,
``datasets`` (name → directory; a scaling study's: its tile map), ``sessions`` (one per start:
started, ended, load averages) and ``fingerprint`` (what decides the rows). A study that runs in
steps records ``levels`` and the ones ``done``. ``timing`` is the timing pass's record
(:meth:`RunDir.start_timing`): its ``fingerprint`` (the run's, the pass's parameters), its
``sessions`` and whether it is ``complete``; :meth:`RunDir.discard` removes it with the pass's
files. ``verdict`` records the truth-free verdict (:meth:`RunDir.record_verdict`) and ``derived``
what each producer of tables derived them from (:meth:`RunDir.record_derived`).
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from tfloc.core.presets import resolve
from tfloc.core.run import (
    DerivedRecord,
    GitState,
    Machine,
    RunDataset,
    RunMatcher,
    RunRecord,
    Session,
    TimingRecord,
    VerdictRecord,
)
from tfloc.core.runconfig import RunConfig
from tfloc.core.thresholds import Thresholds
from tfloc.errors import ConfigError, ResultsError, TflocError

from .atomic import replace_atomically
from .estimates import REQUIRED, read_estimates
from .scenario import SINGLE, read_scenario
from .table import Table, read_frame, read_rows, write
from .tables import VERDICT_FILES
from .text import parse_text

RUN_JSON = "run.json"
ESTIMATES = "estimates.csv"

#: the run.json fields a reader relies on, and what each must be
_FIELDS = {"config": dict, "git": dict, "machine": dict, "versions": dict, "datasets": dict, "sessions": list,
           "declared": dict, "timing": dict, "verdict": dict, "derived": dict, "levels": list, "done": list,
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


def _base(name: str, recorded: object) -> str:
    """The registered matcher a configured name stands for: as the fingerprint recorded it, else
    its preset resolved (the name itself if it is neither)."""
    if isinstance(recorded, dict) and isinstance(recorded.get("matcher"), str):
        return recorded["matcher"]
    try:
        return resolve(name, {})[0]
    except TflocError:
        return name


def _declared(doc: dict, name: str, path: Path) -> dict:
    """What a dataset declares in its ``scenario.json`` (``mode``, ``paper_scenarios``): read
    from the dataset if it is on disk, else as the run recorded it (``declared``)."""
    try:
        sc = read_scenario(path)
        return {"mode": sc.mode, "paper_scenarios": list(sc.paper_scenarios)}
    except TflocError:
        return dict(doc.get("declared", {}).get(name, {}))


def run_of(doc: dict, path: Path) -> RunRecord:
    """The :class:`~tfloc.core.run.RunRecord` of a checked ``run.json`` document (``path`` names
    the file in errors): the configuration read back, each matcher's base name and resolved
    parameters, each dataset's mode read once, every record typed."""
    cfg = doc.get("config", {})
    config = None
    if cfg.get("kind", "bench") == "bench" and "datasets" in cfg and "matchers" in cfg:
        try:
            config = RunConfig.from_dict(cfg)
        except ConfigError as exc:
            raise ResultsError(f"{path}: {exc}") from None
    recorded = (doc.get("fingerprint") or {}).get("matchers") or {}
    matchers = []
    for m in cfg.get("matchers", []):
        rec = recorded.get(m["label"]) if isinstance(recorded, dict) else None
        params = dict(m.get("params", {}))
        resolved = rec.get("params") if isinstance(rec, dict) and isinstance(rec.get("params"), dict) else params
        matchers.append(RunMatcher(m["label"], m["name"], _base(m["name"], rec), params, resolved))
    datasets = []
    for name, where in doc.get("datasets", {}).items():
        declared = _declared(doc, name, Path(where))
        datasets.append(RunDataset(name, Path(where), str(declared.get("mode", SINGLE)),
                                   tuple(declared.get("paper_scenarios", ()))))
    timing = TimingRecord.from_dict(doc["timing"]) if isinstance(doc.get("timing"), dict) else None
    verdict = VerdictRecord.from_dict(doc["verdict"]) if isinstance(doc.get("verdict"), dict) else None
    return RunRecord(config, cfg.get("name"), str(cfg.get("kind", "bench")), dict(cfg.get("scaling") or {}),
                     tuple(matchers), tuple(datasets), Thresholds.from_run(doc), dict(doc.get("versions") or {}),
                     GitState.from_dict(doc.get("git")), Machine.from_dict(doc.get("machine")),
                     tuple(Session.from_dict(x) for x in doc.get("sessions", [])), doc.get("fingerprint"),
                     timing, verdict, {k: DerivedRecord.from_dict(v) for k, v in (doc.get("derived") or {}).items()},
                     tuple(doc.get("levels", [])), tuple(doc.get("done", [])), doc.get("command"), True)


def _file(name: str, what: str) -> property:
    """A run directory's file ``name`` as a read-only attribute (``what`` it holds)."""
    return property(lambda self: self.path / name, doc=f"{what}: {name}")


@dataclass(frozen=True)
class RunDir:
    """A run directory (the files of one run configuration)."""

    path: Path

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))

    estimates = _file(ESTIMATES, "the rows")
    run_json = _file(RUN_JSON, "the run's record")
    timing_md = _file("timing.md", "the timing pass's summary")
    report = _file("report.md", "the report")
    figures = _file("figures", "the report's figures")

    def file(self, table: Table) -> Path:
        """Where the run keeps ``table``."""
        return self.path / table.name

    def has(self, table: Table) -> bool:
        """Whether the run has ``table``'s file."""
        return self.file(table).is_file()

    def read(self, table: Table) -> list:
        """``table``'s rows (its row type; none when the file is missing): :mod:`tfloc.io.table`."""
        return read_rows(self.file(table), table)

    def frame(self, table: Table):
        """``table`` as a typed table (empty when the file is missing): :mod:`tfloc.io.table`."""
        return read_frame(self.file(table), table)

    def write(self, table: Table, rows) -> Path:
        """``rows`` (``table``'s row type, or a table of its columns) into its file, atomically."""
        return write(self.file(table), table, rows)

    def remove(self, *tables: Table) -> None:
        """Remove the files of ``tables`` (those missing are fine)."""
        for t in tables:
            self.file(t).unlink(missing_ok=True)

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

    def info(self, required: bool = False) -> RunRecord:
        """``run.json``, read and checked once (:func:`run_of`); without one, an empty
        :class:`~tfloc.core.run.RunRecord` (or, if ``required``, a :class:`ResultsError`)."""
        doc = self._doc(required)
        return run_of(doc, self.run_json) if doc else RunRecord()

    def rows_sha256(self) -> str | None:
        """SHA-256 of ``estimates.csv`` (``None`` without one): what derived tables record they
        were made from."""
        return _sha256(self.estimates)

    def table_sha256(self, table: Table) -> str | None:
        """SHA-256 of ``table``'s file (``None`` without one)."""
        return _sha256(self.file(table))

    def record_verdict(self, record: VerdictRecord) -> None:
        """Record in ``run.json`` the truth-free verdict just written."""
        self._set({"verdict": record.to_dict()})

    def record_derived(self, producer: str, record: DerivedRecord) -> None:
        """Record in ``run.json`` what ``producer``'s tables were derived from."""
        doc = self._doc()
        self._set({"derived": {**doc.get("derived", {}), producer: record.to_dict()}})

    def record_levels(self, done: list[str], **session: Any) -> None:
        """Record the levels a stepped study has done, and update its last session with
        ``session`` (e.g. its CPU seconds so far)."""
        self._set({"done": list(done)}, **session)

    def recorded_fingerprint(self) -> dict | None:
        """The fingerprint ``run.json`` records, or None if there is none or it is unreadable
        (a resume then reports that the run records no fingerprint)."""
        try:
            return self._doc().get("fingerprint")
        except ResultsError:
            return None

    def _doc(self, required: bool = False) -> dict:
        """``run.json``'s document, read and checked (``{}`` without one; with ``required``, a
        :class:`ResultsError` unless it names the run's matchers and datasets)."""
        if not self.run_json.is_file():
            if required:
                raise ResultsError(f"{self.path}: needs {RUN_JSON} (run 'tfloc bench' first)")
            return {}
        doc = parse_text(self.run_json, ResultsError, "run.json file", json.loads, ValueError, "JSON")
        doc = check_run_doc(doc, self.run_json)
        if required and (not doc.get("config", {}).get("matchers") or not doc.get("datasets")):
            raise ResultsError(f"{self.run_json}: no 'config.matchers' or 'datasets' (not written by tfloc bench?)")
        return doc

    def write_doc(self, doc: dict[str, Any]) -> None:
        """Write ``run.json`` atomically (a temporary file, fsynced, renamed)."""
        replace_atomically(self.run_json, lambda fh: fh.write(json.dumps(doc, indent=2) + "\n"))

    def start_session(self, doc: dict[str, Any], n_tasks: int, n_done: int, loadavg: list | None,
                      **extra: Any) -> None:
        """Write ``run.json`` for a new session: ``doc`` (configuration, environment, datasets,
        fingerprint) with the sessions so far plus this one (``n_tasks`` tasks, ``n_done`` of them
        done before, ``extra`` fields, e.g. the cores it is pinned to); the records of the timing
        pass, the verdict and the derived tables are kept (each says itself whether it is still
        current: its fingerprint, the hash of the rows it read)."""
        try:
            old = self._doc()
        except ResultsError:
            old = {}
        session = {"started": _now(), "tasks": n_tasks, "already_done": n_done, "loadavg_start": loadavg,
                   **extra}
        kept = {k: old[k] for k in ("timing", "verdict", "derived") if k in old and k not in doc}
        self.write_doc({**doc, **kept, "sessions": list(old.get("sessions", [])) + [session]})

    def _set(self, fields: dict[str, Any], **session: Any) -> None:
        """Replace top-level ``fields`` of ``run.json`` and update the last session with
        ``session`` (a run without ``run.json`` has no record to keep them in)."""
        doc = self._doc()
        if not doc:
            return
        doc.update(fields)
        if session and doc.get("sessions"):
            doc["sessions"][-1].update(session)
        self.write_doc(doc)

    def close_session(self, loadavg: list | None, **extra: Any) -> None:
        """Record the end time and load average of the last session (and ``extra`` fields)."""
        try:
            doc = self._doc()
        except ResultsError:
            return
        if doc.get("sessions"):
            doc["sessions"][-1].update(ended=_now(), loadavg_end=loadavg, **extra)
            self.write_doc(doc)

    def start_timing(self, fingerprint: dict[str, Any], loadavg: list | None, fresh: bool) -> None:
        """Record in ``run.json`` that a timing pass of ``fingerprint`` starts (not complete until
        :meth:`close_timing`): a new session, after the sessions of the same pass unless
        ``fresh`` (another pass: its record starts over)."""
        doc = self._doc(required=True)
        old = doc.get("timing") or {}
        previous = [] if fresh or old.get("fingerprint") != fingerprint else list(old.get("sessions", []))
        session = {"started": _now(), "loadavg_start": loadavg}
        doc["timing"] = {"fingerprint": fingerprint, "complete": False, "sessions": previous + [session]}
        self.write_doc(doc)

    def close_timing(self, loadavg: list | None, **extra: Any) -> None:
        """Record that the timing pass started last is complete (``timing.csv`` and ``timing.md``
        are written and current), with ``extra`` fields of its session (e.g. its cores)."""
        doc = self._doc(required=True)
        record = doc.get("timing") or {"sessions": [{}]}
        record["sessions"][-1].update(ended=_now(), loadavg_end=loadavg, **extra)
        doc["timing"] = {**record, "complete": True}
        self.write_doc(doc)

    def discard_products(self) -> None:
        """Remove what was made from the rows that a change of rows makes stale: the timing pass
        (``timing.csv``, ``timing.md`` and its record) and the truth-free verdict's files."""
        from .tables import TIMING

        for f in (self.file(TIMING), self.timing_md, *(self.file(t) for t in VERDICT_FILES)):
            f.unlink(missing_ok=True)
        try:
            doc = self._doc()
        except ResultsError:  # a damaged record: discard removes it whole
            return
        if doc.pop("timing", None) is not None:
            self.write_doc(doc)

    def discard(self, also: tuple[str, ...] = ()) -> None:
        """Remove the run's results, its timing pass and truth-free verdict
        (:meth:`discard_products`), ``run.json`` and the files named ``also`` (``--regenerate``)."""
        self.discard_products()
        for f in (self.estimates, *(self.path / n for n in also), self.run_json):
            f.unlink(missing_ok=True)

    def make(self) -> None:
        """Create the directory (a :class:`ResultsError` if it cannot be)."""
        try:
            self.path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ResultsError(f"{self.path}: cannot create the run directory ({exc.strerror or exc})") from None


def _sha256(path: Path) -> str | None:
    if not path.is_file():
        return None
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def _now() -> str:
    """The local time as ``run.json`` records it (ISO 8601 with the offset)."""
    return time.strftime("%Y-%m-%dT%H:%M:%S%z")
