"""What ``tfloc localize`` and ``tfloc track`` share: one registered matcher from ``--matcher``
and its ``--param KEY=VALUE`` options, built (and checked) before anything runs."""

from __future__ import annotations

import tomllib

from tfloc.errors import ConfigError
from tfloc.harness.config import MatcherSpec
from tfloc.harness.preflight import build_matcher
from tfloc.harness.workspace import load_matcher


def parse_params(items: list[str]) -> dict:
    """``KEY=VALUE`` options as a dict; VALUE is read as TOML (a bare word is a string); a dotted
    KEY sets a field of a nested configuration (``index.step=0.5`` → ``{"index": {"step": 0.5}}``)."""
    out: dict = {}
    for item in items:
        key, eq, text = item.partition("=")
        key = key.strip()
        if not eq or not key:
            raise ConfigError(f"--param {item!r}: expected KEY=VALUE")
        try:
            value = tomllib.loads(f"v = {text}")["v"]
        except tomllib.TOMLDecodeError:
            value = text
        *heads, last = key.split(".")
        node = out
        for h in heads:
            node = node.setdefault(h, {})
            if not isinstance(node, dict):
                raise ConfigError(f"--param {key}: {h} is given both as a value and as a table")
        node[last] = value
    return out


def matcher_from_args(name: str, param_items: list[str], command: str):
    """The matcher ``name`` with the ``--param`` options, built once; a bad parameter is a
    one-line :class:`ConfigError` naming its ``--param``."""
    if ":" in name:
        raise ConfigError(f"--matcher {name}: {command} runs registered matchers only")
    params = parse_params(param_items)
    given = [item.partition("=")[0].strip() for item in param_items]
    keys = {**{k.split(".")[0]: f"--param {k}" for k in given}, **{k: f"--param {k}" for k in given}}
    spec = MatcherSpec.make(name, params, where=f"--matcher {name}", keys=keys)
    build_matcher(spec)
    return load_matcher(spec.name, spec.params_json)
