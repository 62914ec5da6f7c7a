"""What decides a run's rows (its fingerprint), and which rows a change makes stale.

:func:`fingerprint` records a content hash (SHA-256) of each dataset's ``scans.csv``,
``scenario.json`` and map file(s), each matcher label with its *resolved* parameters (defaults
included, so a changed default shows) and the code that decides its rows
(:mod:`tfloc.harness.identity`: a tfloc matcher's import closure with the harness's row code; a
plugin's distribution, version and source; an external program's version and configuration
file's hash, :meth:`tfloc.core.external.ExternalProgram.identity`), and the success thresholds.
``tfloc.files`` lists every file of those closures with its hash, so that a difference can name
the files that changed. ``run.json`` records it.

A run directory is resumed only by a run with the same fingerprint (:func:`differences` says what
changed, one phrase each); :func:`stale` says which rows a change makes stale: a matcher's whose
code, parameters or program changed, a dataset's whose files changed, every row when the
thresholds changed (a row's outcome is scored as it is written). ``jobs``, ``timeout_s`` and
``limit_per_group`` are not in it: they decide how many tasks run and how fast, not what a
finished row holds (timed-out rows can be run again with ``--retry-errors``).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tfloc.core.matcher import factory_of
from tfloc.errors import TflocError
from tfloc.io.maps import map_files
from tfloc.io.scenario import Scenario

from .config import RunConfig
from .identity import ROW_CODE, files_of, tfloc_version


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


def code_files(matchers: dict[str, dict[str, Any]], row_code: tuple[str, ...] = ROW_CODE) -> dict[str, str]:
    """Every file that decides a row of ``matchers`` (label → record), with its hash."""
    out: dict[str, str] = {}
    for rec in matchers.values():
        try:
            out.update(files_of(factory_of(rec["name"]), row_code))
        except TflocError:
            continue
    return dict(sorted(out.items()))


def fingerprint(config: RunConfig, matchers: dict[str, dict[str, Any]],
                scenarios: list[Scenario]) -> dict[str, Any]:
    """What decides the rows of a run (see the module notes; ``matchers`` as
    :func:`tfloc.harness.preflight.build_matchers` gives them, ``scenarios`` the run's datasets,
    read once); JSON-serialisable."""
    return {"tfloc": {"version": tfloc_version(), "files": code_files(matchers)},
            "datasets": {sc.name: dataset_hashes(sc) for sc in scenarios},
            "matchers": matchers, "success": config.success.to_dict()}


_CODE = ("code", "module", "distribution", "version", "source", "rows", "program")


def _flat(d: Any, prefix: str = "") -> dict[str, Any]:
    if isinstance(d, dict) and d:
        out: dict[str, Any] = {}
        for k, v in d.items():
            out.update(_flat(v, f"{prefix}.{k}" if prefix else str(k)))
        return out
    return {prefix: d}


def _show(v: Any) -> str:
    return "(none)" if v is None else json.dumps(v) if not isinstance(v, str) else v


def _short(labels: list[str], most: int = 6) -> str:
    return ", ".join(labels[:most]) + (f" and {len(labels) - most} more" if len(labels) > most else "")


def changed_files(old: dict, new: dict) -> list[str]:
    """The files of tfloc's code whose hash differs between two fingerprints (added or removed
    from the closures included), in path order."""
    a = ((old.get("tfloc") or {}) if isinstance(old.get("tfloc"), dict) else {}).get("files") or {}
    b = (new.get("tfloc") or {}).get("files") or {}
    return sorted(f for f in {*a, *b} if a.get(f) != b.get(f))


def _code_changed(a: dict, b: dict) -> bool:
    return any(a.get(f) != b.get(f) for f in _CODE)


def _plugin_changes(label: str, a: dict, b: dict) -> list[str]:
    """What changed in the plugin or program behind one matcher label."""
    out = []
    if a.get("code") != b.get("code") or a.get("module") != b.get("module"):
        return [f"{label}: now answered by {b.get('module') or 'tfloc'} (was {a.get('module') or a.get('code') or 'unknown code'})"]
    if a.get("version") != b.get("version") or a.get("distribution") != b.get("distribution"):
        out.append(f"{label}: {a.get('distribution') or '(no distribution)'} {_show(a.get('version'))} → "
                   f"{b.get('distribution') or '(no distribution)'} {_show(b.get('version'))}")
    if a.get("program") != b.get("program"):
        pa, pb = a.get("program") or {}, b.get("program") or {}
        out += [f"{label}: program.{k} {_show(pa.get(k))} → {_show(pb.get(k))}"
                for k in dict.fromkeys([*pb, *pa]) if pa.get(k) != pb.get(k)]
    if a.get("code") == "plugin" and a.get("source") != b.get("source"):
        out.append(f"{label}: source changed")
    return out


@dataclass(frozen=True)
class Staleness:
    """Which rows of a recorded run a new fingerprint makes stale: the matcher labels (code,
    parameters or program changed, or no longer in the run), the datasets (files changed or
    gone), or all of them (thresholds changed, or the record is too old to tell)."""

    matchers: frozenset[str] = frozenset()
    datasets: frozenset[str] = frozenset()
    everything: bool = False
    reasons: tuple[str, ...] = field(default=())

    def __bool__(self) -> bool:
        return bool(self.reasons)

    def keeps(self, key: tuple[str, str, str]) -> bool:
        """Whether the row of ``key`` (dataset, scan_id, matcher) stays current."""
        return not self.everything and key[0] not in self.datasets and key[2] not in self.matchers


def stale(old: dict | None, new: dict) -> Staleness:
    """What a change from the recorded fingerprint ``old`` to ``new`` makes stale, with one
    phrase per difference (module notes); empty (false) when nothing differs."""
    if not isinstance(old, dict):
        why = "the run records no fingerprint (made by an older tfloc, or run.json is missing)"
        return Staleness(everything=True, reasons=(why,))
    reasons: list[str] = []
    matchers: set[str] = set()
    datasets: set[str] = set()
    everything = False
    a_m, b_m = old.get("matchers") or {}, new["matchers"]
    reasons += [f"matcher {k} added" for k in b_m if k not in a_m]
    gone = [k for k in a_m if k not in b_m]
    reasons += [f"matcher {k} removed" for k in gone]
    matchers |= set(gone)
    code = []
    for k in (k for k in b_m if k in a_m and a_m[k] != b_m[k]):
        a, b = a_m[k], b_m[k]
        if _code_changed(a, b):
            matchers.add(k)
            reasons += _plugin_changes(k, a, b)
            same_kind = a.get("code") == b.get("code")
            if same_kind and a.get("source") != b.get("source") and a.get("code") == "tfloc" or \
                    same_kind and a.get("rows") != b.get("rows") and a.get("code") == "plugin":
                code.append(k)
        fa, fb = (_flat({f: v for f, v in x.items() if f not in _CODE}) for x in (a, b))
        changed = [f for f in dict.fromkeys([*fb, *fa]) if fa.get(f) != fb.get(f)]
        if changed:
            matchers.add(k)
            reasons += [f"{k}: {c.removeprefix('params.')} {_show(fa.get(c))} → {_show(fb.get(c))}" for c in changed]
    if code:
        files = changed_files(old, new)
        where = f" ({_short(files, 3)})" if files else ""
        if any("source" not in a_m[k] for k in code):
            where = " (the run records no per-matcher code identity: made by an older tfloc)"
        reasons.insert(0, f"code changed for {_short(sorted(code, key=list(b_m).index))}{where}")
    a_d, b_d = old.get("datasets") or {}, new["datasets"]
    reasons += [f"dataset {k} added" for k in b_d if k not in a_d]
    for k in a_d:
        if k not in b_d:
            reasons.append(f"dataset {k} removed")
            datasets.add(k)
        elif a_d[k] != b_d[k]:
            fa, fb = _flat(a_d[k]), _flat(b_d[k])
            changed = [f for f in dict.fromkeys([*fb, *fa]) if fa.get(f) != fb.get(f)]
            reasons.append(f"dataset {k}: {', '.join(c.removeprefix('map:') for c in changed)} changed")
            datasets.add(k)
    for k, v in new["success"].items():
        if (old.get("success") or {}).get(k) != v:
            reasons.append(f"success {k} {_show((old.get('success') or {}).get(k))} → {_show(v)}")
            everything = True
    return Staleness(frozenset(matchers), frozenset(datasets), everything, tuple(reasons))


def differences(old: dict | None, new: dict) -> list[str]:
    """What differs between a recorded fingerprint and a new one, one phrase per difference
    (e.g. ``csm-corr: sigma 0.1 → 0.2``, ``code changed for tf-plus (tfloc/tfplus/cost.py)``);
    empty when they are the same."""
    return list(stale(old, new).reasons)
