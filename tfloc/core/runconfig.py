"""A run's configuration as values: which matchers (:class:`MatcherSpec`) on which datasets, with
which limits and thresholds (:class:`RunConfig`). Distances in metres, angles in radians, times in
seconds.

Study files are parsed into these by :mod:`tfloc.harness.config`; ``run.json`` stores
:meth:`RunConfig.to_dict` and :meth:`RunConfig.from_dict` reads it back (the same value, so a
recorded run can be run, timed and reported again without its study file).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from tfloc.core.thresholds import Thresholds
from tfloc.errors import ConfigError

#: steps a study file may declare: ``index`` (tf-global's place index of every dataset's map)
#: runs before the run, the others after it in the order written
STEPS_BEFORE = ("index",)
STEPS_AFTER = ("timing", "verdict", "report", "robustness", "real-note")
STEPS = (*STEPS_BEFORE, *STEPS_AFTER)
DEFAULT_STEPS = ("report",)


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
    steps: tuple[str, ...] = DEFAULT_STEPS
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

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> RunConfig:
        """The configuration :meth:`to_dict` wrote (``run.json``'s ``config``); a missing or
        malformed field is a :class:`ConfigError` naming it."""
        return _from_dict(d)

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "out": str(self.out), "datasets": [str(d) for d in self.datasets],
                "matchers": [{"label": m.label, "name": m.name, "params": m.params} for m in self.matchers],
                "jobs": self.jobs, "timeout_s": self.timeout_s, "limit_per_group": self.limit_per_group,
                **({"sequence_timeout_s": self.sequence_timeout_s} if self.sequence_timeout_s != 3600.0 else {}),
                **({"skip_per_group": dict(self.skip_per_group)} if self.skip_per_group else {}),
                "success": self.success.to_dict(), "steps": list(self.steps), **self.extra}


#: the fields :meth:`RunConfig.to_dict` writes (and :meth:`RunConfig.from_dict` reads)
_FIELDS = ("name", "out", "datasets", "matchers", "jobs", "timeout_s", "limit_per_group", "sequence_timeout_s",
           "skip_per_group", "success", "steps")


def _from_dict(d: Mapping[str, Any]) -> RunConfig:
    """:meth:`RunConfig.from_dict` (a :class:`ConfigError` naming the field at fault)."""
    if not isinstance(d, Mapping):
        raise ConfigError("config: expected a table")
    for key in ("name", "datasets", "matchers"):
        if key not in d:
            raise ConfigError(f"config: no {key!r}")
    if not isinstance(d["datasets"], list) or not all(isinstance(x, str) for x in d["datasets"]):
        raise ConfigError("config.datasets: expected a list of paths")
    matchers = []
    for i, m in enumerate(d["matchers"] if isinstance(d["matchers"], list) else [None]):
        if not (isinstance(m, Mapping) and isinstance(m.get("name"), str) and isinstance(m.get("params", {}), Mapping)):
            raise ConfigError(f"config.matchers[{i}]: expected a table {{label, name, params}}")
        matchers.append(MatcherSpec.make(m["name"], dict(m.get("params", {})), m.get("label")))
    skips = d.get("skip_per_group", {})
    steps = d.get("steps", list(DEFAULT_STEPS))
    if not isinstance(skips, Mapping) or not isinstance(steps, list):
        raise ConfigError("config.skip_per_group or config.steps: expected a table and a list")
    try:
        return RunConfig(
            name=str(d["name"]), out=Path(str(d.get("out", f"results/{d['name']}"))),
            datasets=tuple(Path(x) for x in d["datasets"]), matchers=tuple(matchers),
            jobs=int(d.get("jobs", 2)), timeout_s=float(d.get("timeout_s", 60.0)),
            limit_per_group=int(d.get("limit_per_group", 0)),
            sequence_timeout_s=float(d.get("sequence_timeout_s", 3600.0)),
            success=Thresholds.from_dict(dict(d.get("success", {}))),
            skip_per_group=tuple((str(k), int(v)) for k, v in skips.items()), steps=tuple(str(x) for x in steps),
            extra={k: v for k, v in d.items() if k not in _FIELDS})
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"config: {exc}") from None
