"""Run configurations: which matchers on which datasets, with which limits (TOML ↔ RunConfig).

A run configuration file looks like (relative paths are relative to where tfloc runs)::

    name = "paper-protocol"
    out = "results/paper-protocol"
    datasets = ["data/scenarios/office-pool", { path = "data/scenarios/detail-1", skip_per_group = 40 }]
    matchers = ["tf", "csm-corr", { label = "tf-S0.5", name = "tf", params = { spacing = 0.5 } }]
    jobs = 2                   # worker processes
    timeout_s = 60             # per (scan, matcher) task
    sequence_timeout_s = 3600  # per (sequence, matcher) task of a sequence dataset
    limit_per_group = 0        # 0 = all scans; N = the first N scans of each group (smoke runs)
    [success]
    dist_m = 0.10
    orient_deg = 2.0
    [params.tf]                # for every matcher entry named "tf" without its own params
    spacing = 1.0
    [[sweep]]                  # one matcher label per point of the grid, in the order written:
    name = "tf"                # tf[spacing=0.5,straw_t=0.95], tf[spacing=0.5,straw_t=0.99], ...
    grid = { spacing = [0.5, 1.0], straw_t = [0.95, 0.99] }
    params = { }               # optional, over [params.tf]; label = "tf": optional label prefix

``skip_per_group`` skips the first N scans of each group (a held-out selection after a development
split). A configuration is a *study file* (:func:`load_study`): ``extends = "other.toml"`` takes
that file's keys (tables merged key by key; ``name`` and ``out`` are never inherited) with its
own on top (``matchers`` may name a roster: :mod:`tfloc.harness.rosters`), ``steps`` lists what makes its tables after the run (:data:`STEPS`; ``index`` runs
before it) and ``kind = "scaling"`` with a ``[scaling]`` table is the scaling study. A matcher named ``module:Class`` runs that module's code: :func:`check_imports` refuses it
unless imports are allowed (``tfloc bench --allow-import``). Each parameter remembers the key that
set it, so that a bad one is reported by its key (``[params.csm-corr] search_radiuss``).
"""

from __future__ import annotations

import itertools
import json
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tfloc.core.runconfig import (  # noqa: F401 - the run configuration's values, re-exported
    DEFAULT_STEPS,
    STEPS,
    STEPS_AFTER,
    STEPS_BEFORE,
    MatcherSpec,
    RunConfig,
)
from tfloc.core.thresholds import Thresholds
from tfloc.errors import ConfigError
from tfloc.io.text import parse_text

from .rosters import expand

KINDS = ("bench", "scaling")

def _keys(params: dict, key: str) -> dict[str, str]:
    return {k: f"{key}{k}" for k in params}


def _defaults(defaults: dict[str, dict], name: str, where: str) -> tuple[dict, dict[str, str]]:
    """``[params.<name>]`` of a configuration, and the keys of its parameters."""
    params = defaults.get(name, {})
    if not isinstance(params, dict):
        raise ConfigError(f"{where}: [params.{name}] must be a table")
    return params, _keys(params, f"{where}: [params.{name}] ")


def parse_matchers(entries: list, defaults: dict[str, dict], where: str) -> tuple[MatcherSpec, ...]:
    """Matcher entries: a registered name, a table ``{label, name, params}`` or ``@ROSTER``
    (:mod:`tfloc.harness.rosters`)."""
    specs = []
    entries = expand(entries, where)
    for i, e in enumerate(entries):
        at = f"{where}: matchers[{i}]" if where != "--matchers" else f"--matchers {e}"
        if isinstance(e, str):
            params, keys = _defaults(defaults, e, where)
            specs.append(MatcherSpec.make(e, params, where=at, keys=keys))
        elif isinstance(e, dict) and isinstance(e.get("name"), str):
            base, keys = _defaults(defaults, e["name"], where)
            own = e.get("params", {})
            if not isinstance(own, dict):
                raise ConfigError(f"{at}: 'params' must be a table")
            specs.append(MatcherSpec.make(e["name"], {**base, **own}, e.get("label"), at,
                                          {**keys, **_keys(own, f"{at}.params.")}))
        else:
            raise ConfigError(f"{where}: matchers[{i}] must be a name or a table with 'name'")
    return tuple(specs)


def _value_text(v: Any) -> str:
    return v if isinstance(v, str) else json.dumps(v)


def expand_sweeps(sweeps: Any, defaults: dict[str, dict], where: str) -> tuple[MatcherSpec, ...]:
    """Matcher specs of ``[[sweep]]`` tables: one per point of each grid (cartesian product)."""
    if not isinstance(sweeps, list):
        raise ConfigError(f"{where}: 'sweep' must be an array of tables ([[sweep]])")
    specs = []
    for i, sw in enumerate(sweeps):
        at = f"{where}: sweep[{i}]"
        if not isinstance(sw, dict) or not isinstance(sw.get("name"), str):
            raise ConfigError(f"{at} must be a table with a matcher 'name'")
        unknown = sorted(set(sw) - {"name", "grid", "params", "label"})
        if unknown:
            raise ConfigError(f"{at}: unknown key(s) {', '.join(unknown)}")
        grid, fixed = sw.get("grid"), sw.get("params", {})
        if not isinstance(grid, dict) or not grid:
            raise ConfigError(f"{at}: 'grid' must be a non-empty table of parameter lists")
        if not isinstance(fixed, dict):
            raise ConfigError(f"{at}: 'params' must be a table")
        for k, values in grid.items():
            if not isinstance(values, list) or not values:
                raise ConfigError(f"{at}: grid.{k} must be a non-empty list of values")
            if len({json.dumps(v) for v in values}) != len(values):
                raise ConfigError(f"{at}: grid.{k} lists a value twice")
        prefix = str(sw.get("label", sw["name"]))
        base, keys = _defaults(defaults, sw["name"], where)
        keys = {**keys, **_keys(fixed, f"{at}.params.")}
        for point in itertools.product(*grid.values()):
            chosen = dict(zip(grid, point, strict=True))
            label = f"{prefix}[{','.join(f'{k}={_value_text(v)}' for k, v in chosen.items())}]"
            specs.append(MatcherSpec.make(sw["name"], {**base, **fixed, **chosen}, label, f"{at} point {label}",
                                          {**keys, **{k: f"{at}.grid.{k} (point {label})" for k in chosen}}))
    return tuple(specs)


def check_imports(config: RunConfig, allow: bool) -> None:
    """Refuse matchers named ``module:Class`` (running them imports the module: its code runs with
    the rights of whoever starts the run) unless ``allow``."""
    spec = next((m for m in config.matchers if ":" in m.name), None)
    if spec is not None and not allow:
        module = spec.name.partition(":")[0]
        raise ConfigError(f"{spec.where or 'matchers'}: {spec.name!r} names a Python class; running it "
                          f"imports module {module!r}, which runs its code: if you trust this "
                          "configuration, give --allow-import")


def _skips(entries: list, where: str) -> tuple[tuple[str, int], ...]:
    """``skip_per_group`` of dataset entries given as tables ``{path, skip_per_group}``."""
    out = []
    for i, d in enumerate(entries):
        if isinstance(d, dict):
            unknown = sorted(set(d) - {"path", "skip_per_group"})
            if unknown or not isinstance(d.get("path"), str):
                raise ConfigError(f"{where}: datasets[{i}] must be a path or a table {{path, skip_per_group}}"
                                  + (f" (unknown key(s) {', '.join(unknown)})" if unknown else ""))
            n = d.get("skip_per_group", 0)
            if isinstance(n, bool) or not isinstance(n, int) or n < 0:
                raise ConfigError(f"{where}: datasets[{i}].skip_per_group must be a whole number ≥ 0, got {n!r}")
            out.append((d["path"], n))
        elif not isinstance(d, str):
            raise ConfigError(f"{where}: datasets[{i}] must be a path or a table {{path, skip_per_group}}")
    return tuple(out)


def merge_docs(base: dict, own: dict) -> dict:
    """A study file's keys over the file it extends: tables merged key by key, anything else
    replaced; ``name`` and ``out`` are the file's own (never inherited)."""
    out = {k: v for k, v in base.items() if k not in ("name", "out")}
    for k, v in own.items():
        out[k] = merge_docs(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def read_doc(path: Path, seen: tuple[Path, ...] = ()) -> dict:
    """A study file's keys with what it ``extends`` resolved (relative to the file's folder)."""
    doc = parse_text(path, ConfigError, "run configuration", tomllib.loads, tomllib.TOMLDecodeError, "TOML")
    parent = doc.pop("extends", None)
    if parent is None:
        return doc
    if not isinstance(parent, str):
        raise ConfigError(f"{path}: 'extends' must be the path of another study file")
    target = (path.parent / parent).resolve()
    if target in (*seen, path.resolve()):
        raise ConfigError(f"{path}: extends {parent!r}, which extends it back")
    if not target.is_file():
        raise ConfigError(f"{path}: extends {parent!r}: no such file ({target})")
    return merge_docs(read_doc(target, (*seen, path.resolve())), doc)


def _steps(doc: dict, path: Path) -> tuple[str, ...]:
    steps = doc.get("steps", list(DEFAULT_STEPS))
    if not isinstance(steps, list) or not all(isinstance(x, str) for x in steps):
        raise ConfigError(f"{path}: 'steps' must be a list of step names ({', '.join(STEPS)})")
    unknown = [x for x in steps if x not in STEPS]
    if unknown:
        raise ConfigError(f"{path}: unknown step(s) {', '.join(unknown)}; known: {', '.join(STEPS)}")
    return tuple(dict.fromkeys(steps))


@dataclass(frozen=True)
class Study:
    """A study file: what ``tfloc bench FILE`` runs, then the steps that make its tables.
    ``kind`` ``bench``: ``run`` (a :class:`RunConfig`); ``scaling``: ``scaling`` (the fields of
    :class:`tfloc.harness.scaling.StudyConfig` to set, and ``quick``)."""

    path: Path
    name: str
    out: Path
    kind: str = "bench"
    steps: tuple[str, ...] = DEFAULT_STEPS
    run: RunConfig | None = None
    scaling: dict = field(default_factory=dict, compare=False)
    description: str = ""


def load_study(path: str | Path) -> Study:
    """Read a study file (module notes); errors name the file and the key."""
    path = Path(path)
    doc = read_doc(path)
    kind = doc.get("kind", "bench")
    if kind not in KINDS:
        raise ConfigError(f"{path}: kind {kind!r} is not one of {', '.join(KINDS)}")
    name = str(doc.get("name", path.stem))
    out = Path(doc.get("out", f"results/{name}"))
    steps = _steps(doc, path)
    if kind == "scaling":
        unknown = sorted(set(doc) - {"name", "out", "description", "kind", "steps", "scaling"})
        if unknown:
            raise ConfigError(f"{path}: unknown key(s) {', '.join(unknown)} (a scaling study)")
        table = doc.get("scaling", {})
        if not isinstance(table, dict):
            raise ConfigError(f"{path}: [scaling] must be a table")
        return Study(path, name, out, kind, steps, scaling=table, description=str(doc.get("description", "")))
    cfg = config_of(doc, path)
    return Study(path, cfg.name, cfg.out, kind, cfg.steps, run=cfg, description=str(doc.get("description", "")))


def load_config(path: str | Path) -> RunConfig:
    """Read a run configuration (a study file of kind ``bench``); errors name the file and the key."""
    study = load_study(path)
    if study.run is None:
        raise ConfigError(f"{path}: a {study.kind} study, not a run configuration (run it with tfloc bench)")
    return study.run


def config_of(doc: dict, path: Path) -> RunConfig:
    """The :class:`RunConfig` of a study file's keys (``extends`` resolved)."""
    known = {"name", "out", "datasets", "matchers", "jobs", "timeout_s", "limit_per_group",
             "success", "params", "description", "sweep", "sequence_timeout_s", "steps", "kind"}
    unknown = sorted(set(doc) - known)
    if unknown:
        raise ConfigError(f"{path}: unknown key(s) {', '.join(unknown)}")
    if "sweep" in doc:  # a run may consist of sweeps only
        doc.setdefault("matchers", [])
    if not isinstance(doc.get("datasets"), list):
        raise ConfigError(f"{path}: 'datasets' must be a list")
    if "matchers" not in doc:
        raise ConfigError(f"{path}: 'matchers' must be a list or a roster's name")
    success = doc.get("success", {})
    try:
        return RunConfig(
            name=str(doc.get("name", path.stem)),
            out=Path(doc.get("out", f"results/{doc.get('name', path.stem)}")),
            datasets=tuple(Path(d["path"] if isinstance(d, dict) else d) for d in doc["datasets"]),
            skip_per_group=_skips(doc["datasets"], str(path)),
            matchers=parse_matchers(doc["matchers"], doc.get("params", {}), str(path))
            + expand_sweeps(doc.get("sweep", []), doc.get("params", {}), str(path)),
            jobs=int(doc.get("jobs", 2)), timeout_s=float(doc.get("timeout_s", 60.0)),
            sequence_timeout_s=float(doc.get("sequence_timeout_s", 3600.0)),
            limit_per_group=int(doc.get("limit_per_group", 0)),
            success=Thresholds.from_dict(success), steps=_steps(doc, path),
            extra={k: doc[k] for k in ("description",) if k in doc})
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{path}: {exc}") from None
    except ConfigError as exc:
        raise ConfigError(exc if str(exc).startswith(str(path)) else f"{path}: {exc}") from None
