"""List the matchers and presets: name, kind (single-scan, tracker or global) and what each is;
with a NAME, its parameters with their defaults and units, and the presets built on it.

Any name listed here (a registered matcher or a preset) is accepted wherever a matcher name is:
tfloc bench --matchers, tfloc track/localize --matcher, a run configuration's matchers. So is a
label of the form base[key=value,...] (a sweep point or an ablation row), e.g. tf-plus[grid=false].

Examples:
  tfloc matchers
  tfloc matchers tf-plus
  tfloc matchers amcl-tuned
"""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import json
import re
import shutil
import sys
import textwrap

HELP = "list the matchers and presets (kind, parameters with defaults and units)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("name", nargs="?", help="a matcher or preset: show its parameters")


def _plain(text: str) -> str:
    """reStructuredText roles and literals as plain text."""
    text = re.sub(r":\w+:`~?(?:[\w.]+\.)?([^`]+)`", r"\1", text)
    return " ".join(text.replace("``", "").split())


def _first_line(obj: object) -> str:
    """The first sentence of the module docstring of a matcher's class (or of the class's)."""
    module = sys.modules.get(getattr(obj, "__module__", ""), None)
    own, mod = inspect.getdoc(obj) or "", (inspect.getdoc(module) if module else None) or ""
    docs = (own,) if own.startswith("``") and not mod.startswith("``") else (mod, own)
    for doc in docs:
        if not doc:
            continue
        para = _plain(doc.split("\n\n")[0])
        para = re.sub(r"^[\w-]+: ", "", para)
        first = re.split(r"(?<=[.!?])\s", para)[0]
        if first:
            return first
    return ""


def _row(cells: list[str], widths: list[int], total: int) -> str:
    head = "  ".join(c.ljust(w) for c, w in zip(cells[:-1], widths, strict=False))
    room = max(30, total - len(head) - 2)
    wrapped = textwrap.wrap(cells[-1], room, break_on_hyphens=False) or [""]
    pad = " " * (len(head) + 2)
    return "\n".join([f"{head}  {wrapped[0]}", *(pad + w for w in wrapped[1:])])


def _value(v: object) -> str:
    if isinstance(v, tuple):
        v = list(v)
    return v if isinstance(v, str) else json.dumps(v)


def overview() -> str:
    from tfloc.core.matcher import available_matchers, factory_of, kind_of
    from tfloc.core.presets import presets
    from tfloc.errors import MatcherError

    total = shutil.get_terminal_size((100, 20)).columns
    lines = ["Matchers (registered; 'tfloc matchers NAME' shows the parameters):"]
    for name in available_matchers():
        try:
            f = factory_of(name)
            kind, about = kind_of(f), _first_line(f)
            if getattr(f, "EXTERNAL", False):  # an external program (tfloc.core.external)
                about = f"external program: {about}"
        except MatcherError as exc:
            kind, about = "?", f"(not available here: {exc})"
        lines.append(_row([name, kind, about], [16, 11], total))
    lines.append("\nPresets (tfloc/presets.toml: a matcher with named parameters):")
    for p in presets().values():
        try:
            kind = kind_of(factory_of(p.name))
        except MatcherError:
            kind = "?"
        lines.append(_row([p.name, kind, f"{p.about} [{p.matcher}]"], [22, 11], total))
    return "\n".join(lines)


def detail(name: str) -> str:
    from tfloc.core.matcher import factory_of, get_matcher, kind_of
    from tfloc.core.param_docs import describe
    from tfloc.core.presets import presets, resolve

    base, params = resolve(name, {})
    factory = factory_of(name)
    total = shutil.get_terminal_size((100, 20)).columns
    out = [f"{name}: {kind_of(factory)} ({factory.__module__}:{getattr(factory, '__qualname__', factory)})",
           textwrap.fill(_first_line(factory), total, break_on_hyphens=False)]
    table = presets()
    if name in table:
        p = table[name]
        out += [f"preset of {p.matcher}: {p.about}", f"values chosen: {p.chosen}",
                "sets: " + ", ".join(f"{k}={_value(v)}" for k, v in params.items())]
    m = get_matcher(name)
    cfg = getattr(m, "config", None)
    if dataclasses.is_dataclass(cfg) and not isinstance(cfg, type):
        docs = describe(cfg)
        out.append(f"\nParameters ({len(docs)}; --param KEY=VALUE, or params in a run configuration):")
        width = min(34, max(len(d.name) for d in docs)) if docs else 10
        for d in docs:
            out.append(_row([d.name, _value(d.default), _plain(d.doc)], [width, 12], total))
    else:
        out.append("\nNo parameters declared (no configuration dataclass).")
    built_on = [p.name for p in table.values() if resolve(p.name, {})[0] == base and p.name != name]
    if built_on:
        out.append(f"\nPresets of {base}: {', '.join(built_on)}")
    return "\n".join(out)


def run(args: argparse.Namespace) -> int:
    print(detail(args.name) if args.name else overview())
    return 0
