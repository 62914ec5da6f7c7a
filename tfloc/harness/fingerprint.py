"""A run is one configuration: its fingerprint, everything that decides its rows.

:func:`fingerprint` is everything that decides a run's rows: a content hash (SHA-256) of each
dataset's ``scans.csv``, ``scenario.json`` and map file(s), each matcher label with its *resolved*
parameters (defaults included, so a changed default shows), the success thresholds and the code
that answers (:mod:`tfloc.harness.identity`: tfloc's answering source, and each plugin matcher's
distribution, version and source; an external program's version and configuration file's hash,
:meth:`tfloc.core.external.ExternalProgram.identity`). ``run.json`` records it; a run directory is resumed only by a
run with the same fingerprint (:func:`differences` says what changed). ``jobs``, ``timeout_s`` and
``limit_per_group`` are not in it: they decide how many tasks run and how fast, not what a
finished row holds (timed-out rows can be run again with ``--retry-errors``).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from tfloc.io.maps import map_files
from tfloc.io.scenario import Scenario

from .config import RunConfig
from .identity import tfloc_code


def _sha256(path: Path) -> str | None:
    h = hashlib.sha256()
    try:
        with path.open("rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return None
    return h.hexdigest()


def dataset_hashes(scenario: Scenario) -> dict[str, Any]:
    """Content hashes of a dataset's files (``map:<name>`` for its map file(s))."""
    out = {"scenario.json": _sha256(Path(scenario.root) / "scenario.json"), "scans.csv": _sha256(scenario.scans_path)}
    for f in map_files(scenario.map_path):
        out[f"map:{f.name}"] = _sha256(f)
    return out


def fingerprint(config: RunConfig, matchers: dict[str, dict[str, Any]],
                scenarios: list[Scenario]) -> dict[str, Any]:
    """What decides the rows of a run (see the module notes; ``matchers`` as
    :func:`tfloc.harness.preflight.build_matchers` gives them, ``scenarios`` the run's datasets,
    read once); JSON-serialisable."""
    return {"tfloc": tfloc_code(),
            "datasets": {sc.name: dataset_hashes(sc) for sc in scenarios},
            "matchers": matchers, "success": config.success.to_dict()}


_CODE = ("code", "module", "distribution", "version", "source")


def _code_changes(label: str, a: dict, b: dict) -> list[str]:
    """What changed in the code behind one matcher label (its plugin's version or source)."""
    if a.get("code") == b.get("code") == "tfloc" or all(a.get(f) == b.get(f) for f in _CODE):
        return []
    if a.get("code") != b.get("code") or a.get("module") != b.get("module"):
        return [f"{label}: now answered by {b.get('module') or 'tfloc'} (was {a.get('module') or a.get('code') or 'unknown code'})"]
    out = []
    if a.get("version") != b.get("version") or a.get("distribution") != b.get("distribution"):
        out.append(f"{label}: {a.get('distribution') or '(no distribution)'} {_show(a.get('version'))} → "
                   f"{b.get('distribution') or '(no distribution)'} {_show(b.get('version'))}")
    if a.get("source") != b.get("source"):
        out.append(f"{label}: source changed")
    return out


def _flat(d: Any, prefix: str = "") -> dict[str, Any]:
    if isinstance(d, dict) and d:
        out: dict[str, Any] = {}
        for k, v in d.items():
            out.update(_flat(v, f"{prefix}.{k}" if prefix else str(k)))
        return out
    return {prefix: d}


def _show(v: Any) -> str:
    return "(none)" if v is None else json.dumps(v) if not isinstance(v, str) else v


def differences(old: dict | None, new: dict) -> list[str]:
    """What differs between a recorded fingerprint and a new one, one phrase per difference
    (e.g. ``csm-corr: sigma 0.1 → 0.2``); empty when they are the same."""
    if not isinstance(old, dict):
        return ["the run records no fingerprint (made by an older tfloc, or run.json is missing)"]
    out = []
    was, now = old.get("tfloc"), new["tfloc"]
    if not isinstance(was, dict):
        out.append(f"the run was made by tfloc {_show(was)}, which recorded no code identity")
    elif was.get("source") != now["source"]:
        out.append(f"tfloc's code changed (source {str(was.get('source'))[:12]} → {now['source'][:12]})")
    elif was.get("version") != now["version"]:
        out.append(f"tfloc {_show(was.get('version'))} → {_show(now['version'])}")
    for what, key in (("dataset", "datasets"), ("matcher", "matchers")):
        a, b = old.get(key) or {}, new[key]
        out += [f"{what} {k} added" for k in b if k not in a]
        out += [f"{what} {k} removed" for k in a if k not in b]
        for k in (k for k in b if k in a and a[k] != b[k]):
            if what == "matcher":
                out += _code_changes(k, a[k], b[k])
                a_k, b_k = ({f: v for f, v in x.items() if f not in _CODE} for x in (a[k], b[k]))
                if a_k == b_k:
                    continue
            fa, fb = (_flat(a[k]), _flat(b[k])) if what == "dataset" else (_flat(a_k), _flat(b_k))
            changed = [f for f in dict.fromkeys([*fb, *fa]) if fa.get(f) != fb.get(f)]
            if what == "dataset":
                out.append(f"dataset {k}: {', '.join(c.removeprefix('map:') for c in changed)} changed")
            else:
                out += [f"{k}: {c.removeprefix('params.')} {_show(fa.get(c))} → {_show(fb.get(c))}"
                        for c in changed]
    for k, v in new["success"].items():
        if (old.get("success") or {}).get(k) != v:
            out.append(f"success {k} {_show((old.get('success') or {}).get(k))} → {_show(v)}")
    return out
