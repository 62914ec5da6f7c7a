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
split). A matcher named ``module:Class`` runs that module's code: :func:`check_imports` refuses it
unless imports are allowed (``tfloc bench --allow-import``). Each parameter remembers the key that
set it, so that a bad one is reported by its key (``[params.csm-corr] search_radiuss``).
"""

from __future__ import annotations

import itertools
import json
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from tfloc.core.thresholds import Thresholds
from tfloc.errors import ConfigError
from tfloc.io.text import parse_text


@dataclass(frozen=True)
class MatcherSpec:
    """One matcher column of a run: its ``label`` in the results, registered ``name``, ``params``."""

    label: str
    name: str
    params_json: str = "{}"
    where: str = field(default="", compare=False)      # the configuration entry, e.g. "x.toml: matchers[2]"
    keys_json: str = field(default="{}", compare=False)  # parameter → the configuration key that set it

    @property
    def params(self) -> dict[str, Any]:
        return json.loads(self.params_json)

    @classmethod
    def make(cls, name: str, params: dict | None = None, label: str | None = None, where: str = "",
             keys: dict[str, str] | None = None) -> MatcherSpec:
        return cls(label or name, name, json.dumps(params or {}, sort_keys=True), where,
                   json.dumps(keys or {}, sort_keys=True))

    def key_of(self, param: str) -> str:
        """The configuration key that set ``param`` (``a.b`` itself if a key names it, else ``a``,
        which also set ``a[1]``; else the entry that made this spec)."""
        keys = json.loads(self.keys_json)
        top = param.split(".")[0].split("[")[0]
        return keys.get(param) or keys.get(top) or self.where or f"matcher {self.label}"


@dataclass(frozen=True)
class RunConfig:
    """A benchmark run. Distances in metres, angles in radians, times in seconds."""

    name: str
    out: Path
    datasets: tuple[Path, ...]
    matchers: tuple[MatcherSpec, ...]
    jobs: int = 2
    timeout_s: float = 60.0
    limit_per_group: int = 0
    sequence_timeout_s: float = 3600.0
    success: Thresholds = Thresholds()
    skip_per_group: tuple[tuple[str, int], ...] = ()
    extra: dict = field(default_factory=dict, compare=False)

    def skip(self, dataset: Path) -> int:
        """How many of the first scans of each group of ``dataset`` the run skips (a held-out
        selection: the scans after a development split)."""
        return dict(self.skip_per_group).get(str(dataset), 0)

    def __post_init__(self) -> None:
        if not self.datasets:
            raise ConfigError(f"run {self.name!r}: no datasets given")
        if not self.matchers:
            raise ConfigError(f"run {self.name!r}: no matchers given")
        labels = [m.label for m in self.matchers]
        if len(set(labels)) != len(labels):
            raise ConfigError(f"run {self.name!r}: duplicate matcher labels {labels}")
        if self.jobs < 1 or self.timeout_s <= 0 or self.sequence_timeout_s <= 0 or self.limit_per_group < 0 or any(
                n < 0 for _, n in self.skip_per_group):
            raise ConfigError(f"run {self.name!r}: jobs ≥ 1, timeout_s > 0 and limit_per_group ≥ 0 required")

    def with_overrides(self, **kw: Any) -> RunConfig:
        return replace(self, **{k: v for k, v in kw.items() if v is not None})

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "out": str(self.out), "datasets": [str(d) for d in self.datasets],
                "matchers": [{"label": m.label, "name": m.name, "params": m.params} for m in self.matchers],
                "jobs": self.jobs, "timeout_s": self.timeout_s, "limit_per_group": self.limit_per_group,
                **({"sequence_timeout_s": self.sequence_timeout_s} if self.sequence_timeout_s != 3600.0 else {}),
                **({"skip_per_group": dict(self.skip_per_group)} if self.skip_per_group else {}),
                "success": self.success.to_dict(), **self.extra}


def _keys(params: dict, key: str) -> dict[str, str]:
    return {k: f"{key}{k}" for k in params}


def _defaults(defaults: dict[str, dict], name: str, where: str) -> tuple[dict, dict[str, str]]:
    """``[params.<name>]`` of a configuration, and the keys of its parameters."""
    params = defaults.get(name, {})
    if not isinstance(params, dict):
        raise ConfigError(f"{where}: [params.{name}] must be a table")
    return params, _keys(params, f"{where}: [params.{name}] ")


def parse_matchers(entries: list, defaults: dict[str, dict], where: str) -> tuple[MatcherSpec, ...]:
    """Matcher entries: a registered name, or a table ``{label, name, params}``."""
    specs = []
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


def load_config(path: str | Path) -> RunConfig:
    """Read a run configuration TOML file; errors name the file and the key."""
    path = Path(path)
    doc = parse_text(path, ConfigError, "run configuration", tomllib.loads, tomllib.TOMLDecodeError, "TOML")
    known = {"name", "out", "datasets", "matchers", "jobs", "timeout_s", "limit_per_group",
             "success", "params", "description", "sweep", "sequence_timeout_s"}
    unknown = sorted(set(doc) - known)
    if unknown:
        raise ConfigError(f"{path}: unknown key(s) {', '.join(unknown)}")
    if "sweep" in doc:  # a run may consist of sweeps only
        doc.setdefault("matchers", [])
    for key in ("datasets", "matchers"):
        if not isinstance(doc.get(key), list):
            raise ConfigError(f"{path}: '{key}' must be a list")
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
            success=Thresholds.from_dict(success),
            extra={k: doc[k] for k in ("description",) if k in doc})
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{path}: {exc}") from None
    except ConfigError as exc:
        raise ConfigError(exc if str(exc).startswith(str(path)) else f"{path}: {exc}") from None
