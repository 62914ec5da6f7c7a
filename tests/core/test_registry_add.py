"""Adding a tracker to the project is three files: its module, its test and its docs page.

A copy of the package (``tfloc/``, ``baselines/`` inside it as a wheel has it, the docs pages)
gets exactly those three files: a native tracker that coasts on the odometry, declared in its
module (``REGISTRY``) as a member of the ``trackers`` roster. Run from the copy (``PYTHONPATH``):
``tfloc matchers`` lists it and describes it, ``@trackers`` runs it before dead reckoning,
``tfloc site --only-registry`` puts it in docs/matchers.md's table (which is then current),
``tfloc track`` tracks a bundled sequence with it, and its own test passes. No other file of the
copy changes but that generated table."""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
from pathlib import Path

from _paths import ROOT, SCEN

NAME = "coast"

MODULE = '''"""``coast``: a tracker that coasts on the wheel odometry alone (dead reckoning as a native
tracker, ``start``/``step``): the start pose composed with each odometry increment. Metres,
radians."""

from __future__ import annotations

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.map import Map
from tfloc.core.pose import Pose
from tfloc.core.problem import Estimate

REGISTRY = {"coast": {
    "class": "CoastTracker",
    "summary": "a **tracker**: the wheel odometry alone, as a native tracker (no map, no scan)",
    "docs": "baselines/coast.md",
    "rosters": ["trackers"],
}}


class CoastTracker:
    """``coast``: the pose is the start pose composed with every odometry increment."""

    name = "coast"
    METHOD = None  # it never looks at the map (tfloc.core.traits)

    def __init__(self) -> None:
        self.pose: Pose | None = None

    def start(self, map: Map, laser: LaserSpec, pose: Pose) -> None:
        self.pose = pose

    def predict(self, odom_delta: Pose) -> Pose:
        return self.pose.compose(odom_delta)

    def step(self, ranges: np.ndarray, odom_delta: Pose, stamp: float, where: str = "scan") -> Estimate:
        self.pose = self.predict(odom_delta)
        return Estimate(self.pose, True)

    def reset(self, pose: Pose) -> None:
        self.pose = pose
'''

TEST = '''"""coast: started at a pose, it composes the odometry increments; it is a registered tracker."""

import math

import numpy as np

from tfloc import Pose, get_matcher
from tfloc.core.matcher import TRACKER, available_matchers, kind_of


def test_it_composes_the_odometry() -> None:
    t = get_matcher("coast")
    t.start(None, None, Pose(1.0, 2.0, 0.0))
    t.step(np.zeros(3), Pose(1.0, 0.0, math.pi / 2), 0.1)
    est = t.step(np.zeros(3), Pose(1.0, 0.0, 0.0), 0.2)
    assert est.pose.distance_to(Pose(2.0, 3.0, math.pi / 2)) < 1e-12


def test_it_is_a_registered_tracker() -> None:
    assert "coast" in available_matchers() and kind_of(get_matcher("coast")) == TRACKER
'''

PAGE = """# coast

`coast` coasts on the wheel odometry: the start pose composed with every odometry increment, a
native tracker that never reads the map or the scan (the floor `odometry` is, run as a tracker).
"""

#: the three files a new tracker is (paths in the copy; baselines/ is tfloc/baselines/ there)
NEW = {"tfloc/baselines/coast.py": MODULE, "tests/baselines/test_coast.py": TEST,
       "docs/baselines/coast.md": PAGE}


def _copy(dst: Path) -> None:
    skip = shutil.ignore_patterns("__pycache__")
    shutil.copytree(ROOT / "tfloc", dst / "tfloc", ignore=skip)
    shutil.copytree(ROOT / "baselines", dst / "tfloc" / "baselines", ignore=skip)
    for page in (ROOT / "docs").rglob("*.md"):
        (dst / page.relative_to(ROOT).parent).mkdir(parents=True, exist_ok=True)
        shutil.copy2(page, dst / page.relative_to(ROOT))


def _files(root: Path) -> dict[str, bytes]:
    return {f.relative_to(root).as_posix(): f.read_bytes() for f in root.rglob("*")
            if f.is_file() and "__pycache__" not in f.parts}


def test_a_tracker_is_its_module_its_test_and_its_docs_page(tmp_path: Path) -> None:
    copy, out = tmp_path / "copy", tmp_path / "out"
    _copy(copy)
    out.mkdir()
    before = _files(copy)
    for rel, text in NEW.items():
        (copy / rel).parent.mkdir(parents=True, exist_ok=True)
        (copy / rel).write_text(text, encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(copy), "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    env.pop("TFLOC_NUMBA_CACHE_DIR", None)

    def run(*args: str) -> str:
        proc = subprocess.run([sys.executable, *args], cwd=copy, env=env, capture_output=True,
                              text=True, timeout=300)
        assert proc.returncode == 0, (args, proc.stderr[-3000:])
        return proc.stdout

    where = run("-c", "import tfloc.baselines.coast as m, tfloc.core.registry as r; "
                      "print(m.__file__); print(r.declarations()[0].path)").split()
    assert where[0] == str(copy / "tfloc/baselines/coast.py")  # the copy, not the installed tfloc

    listing = run("-m", "tfloc.cli", "matchers").splitlines()
    assert any(line.split()[:2] == [NAME, "tracker"] for line in listing), listing
    assert "coasts on the wheel odometry" in run("-m", "tfloc.cli", "matchers", NAME)

    roster = run("-c", "from tfloc.harness.rosters import expand; print(*expand('trackers', 'x'))")
    assert roster.split()[-2:] == [NAME, "odometry"]

    stale = ("from pathlib import Path; from tfloc.site.build import markdown_files, stale_markdown; "
             "print(*(f.as_posix() for f in stale_markdown(markdown_files(Path('.')), None)))")
    assert run("-c", stale).split() == ["docs/matchers.md"]  # the check the repository's test makes
    run("-m", "tfloc.cli", "site", "--only-registry")
    table = (copy / "docs/matchers.md").read_text(encoding="utf-8")
    assert f"| `{NAME}` | a **tracker**: the wheel odometry alone" in table
    assert "`baselines/coast.py` | [baselines/coast.md](baselines/coast.md) |" in table
    assert run("-c", stale).split() == []

    run("-m", "tfloc.cli", "track", "--dataset", str(SCEN / "seq-quick"), "--matcher", NAME,
        "--out", str(out / "est.csv"))
    with (out / "est.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 100 and all(r["status"] == "ok" for r in rows)

    run("-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir", str(copy),
        str(copy / "tests/baselines/test_coast.py"))

    changed = {k for k, v in _files(copy).items() if before.get(k) != v}
    assert changed == {*NEW, "docs/matchers.md"}, changed
