"""What ``tfloc localize`` and ``tfloc track`` share: one registered matcher from ``--matcher``
and its ``--param KEY=VALUE`` options, built (and checked) before anything runs."""

from __future__ import annotations

import tomllib

from tfloc.errors import ConfigError
from tfloc.harness.config import MatcherSpec
from tfloc.harness.fingerprint import build_matcher
from tfloc.harness.workspace import load_matcher


def parse_params(items: list[str]) -> dict:
    """``KEY=VALUE`` options as a dict; VALUE is read as TOML (a bare word is a string)."""
    out = {}
    for item in items:
        key, eq, value = item.partition("=")
        if not eq or not key.strip():
            raise ConfigError(f"--param {item!r}: expected KEY=VALUE")
        try:
            out[key.strip()] = tomllib.loads(f"v = {value}")["v"]
        except tomllib.TOMLDecodeError:
            out[key.strip()] = value
    return out


def matcher_from_args(name: str, param_items: list[str], command: str):
    """The matcher ``name`` with the ``--param`` options, built once; a bad parameter is a
    one-line :class:`ConfigError` naming its ``--param``."""
    if ":" in name:
        raise ConfigError(f"--matcher {name}: {command} runs registered matchers only")
    params = parse_params(param_items)
    spec = MatcherSpec.make(name, params, where=f"--matcher {name}", keys={k: f"--param {k}" for k in params})
    build_matcher(spec)
    return load_matcher(spec.name, spec.params_json)
