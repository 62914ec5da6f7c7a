"""Presets: named configurations of registered matchers, defined once in ``tfloc/presets.toml``.

A preset (``amcl-tuned``, ``tf-plus-changed``, …) is accepted wherever a matcher name is: the
command line (``tfloc track --matcher amcl-tuned --param seed=3``), run configurations and
:func:`tfloc.get_matcher`. It names a registered matcher (or another preset) and the parameters
it sets; parameters given on top override them, a nested table field by field. A parameter
value ``{ preset = "NAME" }`` stands for the parameters of preset NAME (e.g. tf-plus-track's
``local`` configuration is tf-plus-changed's), so that no configuration is written twice.

A name of the form ``base[key=value,...]`` (the label of a sweep point or an ablation row, e.g.
``tf-plus[grid=false]`` or ``tf-plus[refinement.inlier_distance=0.05]``) is ``base`` with those
parameters: every configuration a table names can be passed by that name.
"""

from __future__ import annotations

import copy
import re
import tomllib
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

from tfloc.errors import ConfigError, MatcherError

PRESETS_FILE = Path(__file__).resolve().parents[1] / "presets.toml"
_KEYS = {"matcher", "about", "chosen", "params", "mode"}
_LABEL = re.compile(r"^(?P<base>[^\[\]]+)\[(?P<body>.*)\]$")


@dataclass(frozen=True)
class Preset:
    """One named configuration: ``matcher`` (a registered matcher or another preset), its
    ``params``, what it is (``about``, one line), where its values come from (``chosen``: a
    package's shipped file, a development run) and the ``mode`` it is meant for
    (``single``, ``tracking``, ``global`` or empty: any)."""

    name: str
    matcher: str
    params: dict = field(default_factory=dict, hash=False)
    about: str = ""
    chosen: str = ""
    mode: str = ""


def _check(name: str, doc: Any, path: Path) -> Preset:
    if not isinstance(doc, dict):
        raise ConfigError(f"{path}: [{name}] must be a table")
    unknown = sorted(set(doc) - _KEYS)
    if unknown:
        raise ConfigError(f"{path}: [{name}] unknown key(s) {', '.join(unknown)}")
    if not isinstance(doc.get("matcher"), str) or not isinstance(doc.get("params", {}), dict):
        raise ConfigError(f"{path}: [{name}] needs matcher = \"NAME\" and a params table")
    return Preset(name, doc["matcher"], doc.get("params", {}), str(doc.get("about", "")),
                  str(doc.get("chosen", "")), str(doc.get("mode", "")))


@cache
def presets(path: Path = PRESETS_FILE) -> dict[str, Preset]:
    """Every preset of ``path`` by name (read once)."""
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read the presets ({exc})") from None
    return {name: _check(name, body, path) for name, body in doc.items()}


def merge(base: dict, over: dict) -> dict:
    """``base`` with ``over`` on top; tables merge field by field (a copy)."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        out[k] = merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else copy.deepcopy(v)
    return out


def _expand(value: Any, seen: tuple[str, ...]) -> Any:
    """``{preset = NAME}`` tables replaced by that preset's parameters (recursively)."""
    if isinstance(value, dict):
        if set(value) == {"preset"} and isinstance(value["preset"], str):
            return resolve(value["preset"], {}, seen)[1]
        return {k: _expand(v, seen) for k, v in value.items()}
    return value


def label_params(text: str) -> tuple[str, dict] | None:
    """``base[key=value,...]`` → ``(base, params)`` (values in TOML syntax, a bare word a
    string, dotted keys into nested tables); ``None`` if ``text`` is not of that form."""
    m = _LABEL.match(text)
    if not m:
        return None
    params: dict = {}
    for item in _split(m["body"]):
        key, eq, raw = item.partition("=")
        if not eq or not key.strip():
            raise MatcherError(f"matcher {text!r}: {item!r} is not KEY=VALUE")
        try:
            value = tomllib.loads(f"v = {raw.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            value = raw.strip()
        *heads, last = key.strip().split(".")
        node = params
        for h in heads:
            node = node.setdefault(h, {})
        node[last] = value
    return m["base"], params


def _split(body: str) -> list[str]:
    """``a=1,b=[1, 2],c=x`` split at the commas outside brackets."""
    out, depth, cur = [], 0, ""
    for ch in body:
        depth += (ch in "[{") - (ch in "]}")
        if ch == "," and depth == 0:
            out.append(cur)
            cur = ""
        else:
            cur += ch
    return [s for s in (*out, cur) if s.strip()]


def resolve(name: str, params: dict, seen: tuple[str, ...] = ()) -> tuple[str, dict]:
    """The registered matcher (or ``module:Class``) that ``name`` stands for, and the
    parameters it runs with: a preset's chain unrolled, a label's bracket parameters read,
    ``params`` on top. A name that is neither is returned as it is."""
    if name in seen:
        raise ConfigError(f"preset {name!r} refers to itself ({' → '.join((*seen, name))})")
    table = presets()
    if name in table:
        p = table[name]
        base, inner = resolve(p.matcher, _expand(p.params, (*seen, name)), (*seen, name))
        return base, merge(inner, params)
    labelled = label_params(name)
    if labelled is not None:
        base, own = labelled
        base, inner = resolve(base, own, (*seen, name))
        return base, merge(inner, params)
    return name, params


def preset_params(name: str) -> dict:
    """The parameters preset ``name`` sets on its registered matcher."""
    return resolve(name, {})[1]
