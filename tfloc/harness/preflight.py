"""Before a run: every matcher built once and every dataset read once, in the calling process,
before any task starts or any file is written.

:func:`build_matcher` builds one matcher (a misspelled parameter or a bad value stops the run with
one line naming the configuration key: ``x.toml: [params.csm-corr] search_radiuss: …``);
:func:`available` leaves out the matchers whose optional library is missing; :func:`preflight`
does both for a run and reads its datasets, giving the :class:`Preflight` the runner makes its
tasks, fingerprint and ``run.json`` from.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tfloc.core.external import ExternalProgram
from tfloc.core.jsonable import jsonable
from tfloc.core.matcher import factory_of
from tfloc.core.presets import resolve
from tfloc.errors import ConfigError, LibraryMissingError, MatcherError, ParameterError
from tfloc.io.scenario import Scenario, read_scenario

from .config import MatcherSpec, RunConfig
from .fingerprint import fingerprint
from .identity import ROW_CODE, matcher_code
from .workspace import load_matcher


def build_matcher(spec: MatcherSpec) -> tuple[Any, dict[str, Any]]:
    """Build the matcher of ``spec`` (cached per process): the matcher and its resolved parameters.

    Raises :class:`ConfigError` naming the configuration key of a bad parameter."""
    try:
        m = load_matcher(spec.name, spec.params_json)
    except ParameterError as exc:
        key = spec.key_of(exc.names[0]) if exc.names else spec.where or f"matcher {spec.label}"
        raise ConfigError(f"{key}: {exc}") from None
    except MatcherError as exc:
        raise ConfigError(f"{spec.where or 'matchers'}: {exc}") from None
    except Exception as exc:  # noqa: BLE001 - a third-party factory may raise anything
        raise ConfigError(f"{spec.where or 'matchers'}: matcher {spec.name!r} cannot be built with "
                          f"{spec.params}: {type(exc).__name__}: {exc}") from None
    cfg = getattr(m, "config", None)
    if dataclasses.is_dataclass(cfg) and not isinstance(cfg, type):
        return m, jsonable(cfg)
    return m, spec.params


def matcher_record(spec: MatcherSpec, row_code: tuple[str, ...] = ROW_CODE) -> dict[str, Any]:
    """The matcher of ``spec`` built once (:func:`build_matcher`): its name, the registered matcher
    it stands for (a preset's or a label's), resolved parameters and the code that decides its
    rows (:func:`tfloc.harness.identity.matcher_code`, with ``row_code`` the harness code that
    writes them); what a fingerprint records of it."""
    m, params = build_matcher(spec)
    record = {"name": spec.name, "matcher": resolve(spec.name, {})[0], "params": params,
              **matcher_code(factory_of(spec.name), row_code)}
    program = getattr(m, "program", None)
    if isinstance(program, ExternalProgram):  # an external program: its version and configuration file
        record["program"] = program.identity()
    return record


def build_matchers(config: RunConfig) -> dict[str, dict[str, Any]]:
    """Every matcher of the run built once: label → :func:`matcher_record`."""
    return {m.label: matcher_record(m) for m in config.matchers}


def available(config: RunConfig, log=None) -> RunConfig:
    """``config`` without the matchers whose library is not installed (e.g. ``karto`` on Python
    ≥ 3.12, where its library has no wheel), each left out with one line to ``log``; the other
    matchers still run. Raises :class:`ConfigError` if none is left."""
    keep = []
    for m in config.matchers:
        try:
            load_matcher(m.name, m.params_json)
        except LibraryMissingError as exc:
            if log is not None:
                log(f"matcher {m.label} left out of this run: {exc}")
            continue
        except Exception:  # noqa: BLE001 - build_matcher reports every other problem
            pass
        keep.append(m)
    if not keep:
        raise ConfigError(f"run {config.name!r}: no matcher of the run can be built here")
    return config if len(keep) == len(config.matchers) else config.with_overrides(matchers=tuple(keep))


@dataclass(frozen=True)
class Preflight:
    """A run checked before it starts: its configuration (without matchers whose library is
    missing), each dataset read once (directory → :class:`Scenario`), each matcher built once
    (label → name, registered matcher, resolved parameters, code) and the run's fingerprint,
    computed once from them (:func:`tfloc.harness.fingerprint.fingerprint`)."""

    config: RunConfig
    scenarios: dict[Path, Scenario] = field(hash=False)
    matchers: dict[str, dict[str, Any]] = field(hash=False)
    fingerprint: dict[str, Any] = field(hash=False, default_factory=dict)


def preflight(config: RunConfig, log=None) -> Preflight:
    """Check a run before it starts (module notes); raises :class:`ConfigError` for a bad
    parameter or dataset, before anything is written."""
    config = available(config, log=log)
    scenarios = {Path(d): read_scenario(d) for d in config.datasets}
    matchers = build_matchers(config)
    return Preflight(config, scenarios, matchers, fingerprint(config, matchers, list(scenarios.values())))
