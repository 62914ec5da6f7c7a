"""Run configuration (``benchmarks/*.toml``) → a frozen :class:`RunConfig`.

Format::

    name = "paper-protocol"
    out = "results/paper-protocol"          # relative paths: to the current directory
    datasets = ["data/scenarios/office-pool", "data/scenarios/detail-1"]
    matchers = ["tf", "o3d-icp"]            # registered names, or "label=module:Class"
    jobs = 2
    timeout_s = 60.0
    success_dist_m = 0.10
    success_orient_deg = 2.0
    [params.tf]                             # optional keyword overrides per matcher label
    max_iterations = 50
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

from ..errors import ConfigError


@dataclass(frozen=True)
class RunConfig:
    """Everything a ``tfloc bench`` run needs (metres, seconds, degrees for the success angle)."""

    name: str
    out: str
    datasets: tuple[str, ...]
    matchers: tuple[str, ...]
    jobs: int = 2
    timeout_s: float = 120.0
    success_dist_m: float = 0.10
    success_orient_deg: float = 2.0
    params: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.datasets:
            raise ConfigError("run configuration: no datasets")
        if not self.matchers:
            raise ConfigError("run configuration: no matchers")
        if self.jobs < 1:
            raise ConfigError(f"run configuration: jobs must be ≥ 1, got {self.jobs}")
        if not self.timeout_s > 0:
            raise ConfigError(f"run configuration: timeout_s must be > 0, got {self.timeout_s}")

    @property
    def success_orient_rad(self) -> float:
        return math.radians(self.success_orient_deg)

    def matcher_specs(self) -> list[tuple[str, str]]:
        """``(label, spec)`` pairs: ``"tf"`` → ``("tf", "tf")``; ``"x=mod:Cls"`` → ``("x", "mod:Cls")``."""
        out = []
        for m in self.matchers:
            label, eq, spec = m.partition("=")
            out.append((label.strip(), spec.strip()) if eq else (m.strip(), m.strip()))
        labels = [lab for lab, _ in out]
        if len(set(labels)) != len(labels):
            raise ConfigError(f"run configuration: duplicate matcher labels in {labels}")
        return out

    def with_overrides(self, **kw) -> RunConfig:
        """A copy with the non-None keyword values replaced (command-line flags)."""
        return replace(self, **{k: v for k, v in kw.items() if v is not None})

    def to_dict(self) -> dict:
        d = asdict(self)
        d["datasets"], d["matchers"] = list(self.datasets), list(self.matchers)
        return d


_KEYS = {"name", "out", "datasets", "matchers", "jobs", "timeout_s", "success_dist_m",
         "success_orient_deg", "params"}


def load_config(path: str | Path) -> RunConfig:
    """Read a run configuration TOML; errors name the file and the field."""
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such run configuration") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML ({exc})") from None
    unknown = sorted(set(doc) - _KEYS)
    if unknown:
        raise ConfigError(f"{path}: unknown field(s) {', '.join(unknown)}; known: {', '.join(sorted(_KEYS))}")
    for key in ("datasets", "matchers"):
        if not isinstance(doc.get(key), list) or not all(isinstance(v, str) for v in doc[key]):
            raise ConfigError(f"{path}: {key!r} must be a list of strings")
    try:
        return RunConfig(name=str(doc.get("name", path.stem)),
                         out=str(doc.get("out", f"results/{path.stem}")),
                         datasets=tuple(doc["datasets"]), matchers=tuple(doc["matchers"]),
                         jobs=int(doc.get("jobs", 2)), timeout_s=float(doc.get("timeout_s", 120.0)),
                         success_dist_m=float(doc.get("success_dist_m", 0.10)),
                         success_orient_deg=float(doc.get("success_orient_deg", 2.0)),
                         params=dict(doc.get("params", {})))
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{path}: bad value ({exc})") from None
