"""A rerun never reuses rows made by other code, and an edit elsewhere leaves them current: a
matcher's rows are identified by its import closure with the harness's row code (a plugin's by
its distribution, version and source), a rerun after a change of it stops with one line naming
the matchers it touches, ``--regenerate`` re-runs only those, and an edit no matcher imports
leaves the run complete."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from _paths import ROOT

from tfloc.core.matcher import _registry
from tfloc.harness import identity
from tfloc.harness.fingerprint import differences, stale
from tfloc.harness.imports import closure, file_key, module_files

PROBE = '''
from tfloc import Estimate, Pose


class Probe:
    name = "probe"

    def localize(self, problem):
        g = problem.initial
        return Estimate(Pose(g.x + {shift}, g.y, g.theta), converged=True)
'''


def _bench(tmp: Path, *extra: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp / "plugin"), str(ROOT / "tests")])}
    return subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", str(ROOT / "data/scenarios/detail-1"),
                           "--matchers", "byo_probe:Probe", "--allow-import", "--limit-per-group", "1",
                           "--out", str(tmp / "run"), "--jobs", "1", "--no-progress", *extra],
                          cwd=tmp, env=env, capture_output=True, text=True, timeout=600)


def test_a_changed_plugin_is_not_resumed(tmp_path: Path) -> None:
    plugin = tmp_path / "plugin"
    plugin.mkdir()
    (plugin / "byo_probe.py").write_text(PROBE.format(shift="0.0"))
    first = _bench(tmp_path)
    assert first.returncode == 0, first.stderr
    fp = json.loads((tmp_path / "run" / "run.json").read_text())["fingerprint"]
    code = fp["matchers"]["byo_probe:Probe"]
    assert code["code"] == "plugin" and code["module"] == "byo_probe" and len(code["source"]) == 64
    assert code["rows"] == identity.code_identity(identity.ROW_CODE)
    assert "tfloc/harness/task.py" in fp["tfloc"]["files"]
    again = _bench(tmp_path)
    assert again.returncode == 0 and "already complete: 0 tasks run" in again.stderr, again.stderr
    (plugin / "byo_probe.py").write_text(PROBE.format(shift="0.5"))  # the answer moves half a metre
    changed = _bench(tmp_path)
    lines = changed.stderr.strip().splitlines()
    assert changed.returncode == 2 and len(lines) == 1 and "Traceback" not in changed.stderr, changed.stderr
    assert "byo_probe:Probe: source changed" in lines[0] and "--regenerate" in lines[0]
    redo = _bench(tmp_path, "--regenerate")
    assert redo.returncode == 0, redo.stderr
    rows = (tmp_path / "run" / "estimates.csv").read_text().splitlines()
    header = rows[0].split(",")
    est_x, init_x = header.index("est_x"), header.index("init_x")
    assert all(abs(float(r.split(",")[est_x]) - float(r.split(",")[init_x]) - 0.5) < 1e-6 for r in rows[1:])


def _fp(files: dict[str, str], matchers: dict[str, str]) -> dict:
    return {"tfloc": {"version": "0.1.0", "files": files}, "datasets": {}, "success": {},
            "matchers": {m: {"name": m, "matcher": m, "params": {}, "code": "tfloc", "source": s}
                         for m, s in matchers.items()}}


def test_a_change_names_the_matchers_it_touches_and_the_files() -> None:
    old = _fp({"tfloc/a.py": "1", "tfloc/b.py": "2"}, {"tf": "x", "karto": "y"})
    assert differences(old, old) == [] and not stale(old, old)
    new = _fp({"tfloc/a.py": "1", "tfloc/b.py": "3"}, {"tf": "x", "karto": "z"})
    st = stale(old, new)
    assert st.reasons == ("code changed for karto (tfloc/b.py)",)
    assert st.matchers == {"karto"} and not st.everything
    assert st.keeps(("d", "s1", "tf")) and not st.keeps(("d", "s1", "karto"))
    (why,) = differences({**old, "matchers": {"tf": {"name": "tf", "matcher": "tf", "params": {}, "code": "tfloc"},
                                              "karto": old["matchers"]["karto"]}}, new)
    assert why.startswith("code changed for tf, karto") and "older tfloc" in why


def test_changed_thresholds_make_every_row_stale() -> None:
    old = _fp({}, {"tf": "x"})
    st = stale({**old, "success": {"dist_m": 0.1}}, {**old, "success": {"dist_m": 0.2}})
    assert st.everything and not st.keeps(("d", "s", "tf"))


def test_a_plugin_version_change_is_named() -> None:
    def plug(version: str, source: str) -> dict:
        return {"tfloc": {"files": {}}, "datasets": {}, "success": {},
                "matchers": {"p": {"name": "m:P", "matcher": "m:P", "params": {}, "code": "plugin", "module": "m",
                                   "distribution": "my-matcher", "version": version, "source": source, "rows": "r"}}}
    assert differences(plug("0.1", "s"), plug("0.2", "s")) == ["p: my-matcher 0.1 → my-matcher 0.2"]
    assert differences(plug("0.1", "s"), plug("0.1", "t")) == ["p: source changed"]


def test_a_matchers_code_is_its_import_closure_with_the_row_code() -> None:
    """The closures are what each matcher imports: tf-plus's holds the tf-plus stages and the
    row code, not the baselines; no matcher's holds the presentation layers or a module none
    imports."""
    reg = _registry()
    closures = {n: {file_key(m) for m in closure([t.split(":")[0], *identity.ROW_CODE])} for n, t in reg.items()}
    assert {"tfloc/tfplus/cost.py", "tfloc/harness/task.py", "tfloc/harness/track.py",
            "tfloc/io/scenario.py"} <= closures["tf-plus"]
    assert not any(f.startswith("tfloc/baselines/") for f in closures["tf-plus"])
    assert "tfloc/tfplus/cost.py" not in closures["karto"]
    for name, files in closures.items():
        assert not any(f.split("/")[1] in ("report", "site", "cli") for f in files), name
        assert "tfloc/datasets/spacing.py" not in files, name
    assert all(f in {file_key(m) for m in module_files()} for f in closures["tf"])


def test_git_state_names_the_checkout_of_the_code() -> None:
    state = identity.git_state()
    assert set(state) == {"commit", "dirty"}
    if state["commit"] is not None:
        assert len(state["commit"]) == 40 and isinstance(state["dirty"], bool)


# ---- both directions, on a copy of the package ---------------------------------------------

def _copy_package(dest: Path) -> Path:
    """tfloc's source as installed (``tfloc/`` with ``baselines/`` as ``tfloc/baselines/``)."""
    src = dest / "src"
    shutil.copytree(ROOT / "tfloc", src / "tfloc", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "baselines", src / "tfloc" / "baselines", ignore=shutil.ignore_patterns("__pycache__"))
    return src


def _small_dataset(dest: Path) -> Path:
    """detail-1's first four scans, its map beside them."""
    d = dest / "data" / "tiny"
    d.mkdir(parents=True)
    doc = json.loads((ROOT / "data/scenarios/detail-1/scenario.json").read_text())
    shutil.copy(ROOT / "data/maps/office-1.geojson", d / "office-1.geojson")
    (d / "scenario.json").write_text(json.dumps({**doc, "name": "tiny", "map": "office-1.geojson"}))
    lines = (ROOT / "data/scenarios/detail-1/scans.csv").read_text().splitlines()
    (d / "scans.csv").write_text("\n".join(lines[:5]) + "\n")
    return d


def _edit(path: Path) -> None:
    path.write_text(path.read_text() + "\n# an edit\n")


def test_an_edit_resumes_or_stops_by_what_imports_it(tmp_path: Path) -> None:
    """An edit of a module no matcher imports leaves the run complete (rows kept); an edit of the
    code that derives the tables leaves the rows current and the tables stale, re-made from the
    rows by ``tfloc report`` (no matcher runs); an edit of one matcher's module stops the resume
    with one line naming that matcher alone; ``--regenerate`` re-runs that matcher's tasks only,
    and the tables wait for the next report."""
    src, data = _copy_package(tmp_path), _small_dataset(tmp_path)
    env = {**os.environ, "PYTHONPATH": str(src)}
    env.pop("TFLOC_NUMBA_CACHE_DIR", None)  # the kernels are this checkout's: share its cache
    run = tmp_path / "run"

    def bench(*extra: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "tfloc.cli", "bench", str(data), "--matchers",
                               "o3d-icp,csm-corr", "--out", str(run), "--jobs", "1", "--no-progress", *extra],
                              cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)

    def tfloc(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "tfloc.cli", *args], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=600)

    def derived_stale() -> list[str]:
        code = "import sys; from tfloc.harness.derive import stale; print(stale(sys.argv[1]))"
        return eval(subprocess.run([sys.executable, "-c", code, str(run)], cwd=tmp_path, env=env,  # noqa: S307
                                   capture_output=True, text=True, timeout=300).stdout)

    first = bench()
    assert first.returncode == 0, first.stderr
    assert tfloc("report", str(run), "--no-figures").returncode == 0
    assert derived_stale() == []
    rows = (run / "estimates.csv").read_text()
    for unused in ("datasets/spacing.py", "report/report.py", "site/board.py"):
        _edit(src / "tfloc" / unused)
        again = bench()
        assert again.returncode == 0 and "already complete" in again.stderr, (unused, again.stderr)
        assert (run / "estimates.csv").read_text() == rows
    # the code that derives the tables changes: the rows stay current, the tables are re-made from them
    _edit(src / "tfloc" / "evaluation" / "headline.py")
    assert "already complete" in bench().stderr
    assert derived_stale() == ["the code that derives them changed"]
    stamp = (run / "estimates.csv").stat().st_mtime_ns
    assert tfloc("report", str(run), "--no-figures").returncode == 0
    assert derived_stale() == [] and (run / "estimates.csv").stat().st_mtime_ns == stamp
    _edit(src / "tfloc" / "baselines" / "csm_corr.py")
    stop = bench()
    lines = stop.stderr.strip().splitlines()
    assert stop.returncode == 2 and len(lines) == 1, stop.stderr
    assert "code changed for csm-corr (tfloc/baselines/csm_corr.py)" in lines[0], lines[0]
    assert "o3d-icp" not in lines[0]
    redo = bench("--regenerate")
    assert redo.returncode == 0, redo.stderr
    assert "re-running the tasks of csm-corr" in redo.stderr
    kept = [ln for ln in rows.splitlines() if ",o3d-icp," in ln]
    now = (run / "estimates.csv").read_text().splitlines()
    assert kept and all(ln in now for ln in kept), "o3d-icp's rows are kept as they were"
    assert sum(",csm-corr," in ln for ln in now) == 4
    assert derived_stale() == ["the run's rows changed"]  # the tables wait for tfloc report
