"""Where a recording without reference poses starts: a global matcher run on its first scans.

The matcher (``tf-global`` by default, any registered matcher that ``solves_global``) answers
each of the first ``scans`` scans without a guess; each of its hypotheses, carried back to the
first scan by the odometry between them, is a candidate start. Every candidate is scored on all
those scans (the matcher's own ``score`` at the candidate carried forward by the odometry, mean
over the scans, metres for tf-global: tf-plus's RMS of truncated residuals); the lowest wins.
The start is **ambiguous** when a candidate at least :data:`DISTINCT_M` or
:data:`DISTINCT_RAD` away (tf-plus-track's jump size) scores less than :data:`AMBIGUOUS_RATIO`
times the winner's (tf-plus-track's rule for believing a jump): another place explains the
first scans about as well. The pose and its score are stated in ``scenario.json``'s
``generator.start``, as are an ``--initial-pose`` or ``--initial-topic`` where they were given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tfloc.core.laser import LaserSpec
from tfloc.core.matcher import get_matcher, solves_global
from tfloc.core.pose import Pose, angdiff
from tfloc.core.problem import Problem
from tfloc.errors import BagError, ConfigError

DISTINCT_M = 0.5  #: metres: a candidate this far from the winner is another place ...
DISTINCT_RAD = math.radians(20.0)  #: ... or this far in heading (tf-plus-track's jump size)
AMBIGUOUS_RATIO = 1.5  #: ... and ambiguous if it scores less than this × the winner's
SAME_M, SAME_RAD = 0.2, math.radians(5.0)  #: candidates closer than this are one


@dataclass(frozen=True)
class FirstPose:
    """A sequence's start pose (the laser's, map frame, metres and radians) and how it was found:
    ``source`` ``"reference"`` | ``"initial-pose"`` | ``"initial-topic"`` | ``"global-matcher"``;
    for a global matcher its name, the scans it ran on, the winner's mean score, and the best
    distinct other place (pose and score) with the ambiguity verdict."""

    pose: Pose
    source: str
    detail: str = ""  #: the topic or the matcher
    scans: int = 0
    score: float = math.nan
    runner_up: Pose | None = None
    runner_up_score: float = math.nan
    ambiguous: bool = False

    def record(self) -> dict:
        """For ``scenario.json``'s ``generator.start``."""
        out = {"source": self.source, "pose": [round(v, 6) for v in self.pose.as_array()]}
        if self.detail:
            out["from"] = self.detail
        if self.source == "global-matcher":
            out.update(scans=self.scans, score=_round(self.score), ambiguous=self.ambiguous,
                       runner_up=None if self.runner_up is None else
                       {"pose": [round(v, 6) for v in self.runner_up.as_array()],
                        "score": _round(self.runner_up_score)})
        return out

    def text(self) -> str:
        """One line for the import summary and the dataset's description."""
        p = self.pose
        at = f"({p.x:.3f}, {p.y:.3f} m, {math.degrees(p.theta):.1f}°)"
        if self.source != "global-matcher":
            return f"start {at} from {self.source}" + (f" {self.detail}" if self.detail else "")
        line = f"start {at} found by {self.detail} on the first {self.scans} scans (score {self.score:.4g})"
        if self.runner_up is not None:
            d = self.runner_up.distance_to(self.pose)
            line += (f"; AMBIGUOUS: a place {d:.2f} m away scores {self.runner_up_score:.4g}" if self.ambiguous
                     else f"; next place {d:.2f} m away scores {self.runner_up_score:.4g}")
        return line


def _round(v: float) -> float | None:
    return None if not math.isfinite(v) else float(f"{v:.6g}")


def global_first_pose(the_map, laser: LaserSpec, ranges: np.ndarray, odom: list[Pose],
                      matcher: str = "tf-global", where: str = "") -> FirstPose:
    """The start of a recording found by ``matcher`` on the scans ``ranges`` ``(K, n)`` with the
    laser's odometry poses ``odom`` (K, any frame) at them (module notes). Raises
    :class:`ConfigError` for a matcher that is not global, :class:`BagError` (naming ``where``)
    when it finds no pose."""
    if ":" in matcher:
        raise ConfigError(f"--initial-matcher must be a registered global matcher, got {matcher!r}")
    m = get_matcher(matcher)
    if not solves_global(m):
        raise ConfigError(f"--initial-matcher {matcher} is not a global matcher (it needs a guess); "
                          "try tf-global or bnb-global")
    rel = [odom[0].between(o) for o in odom]  # scan k's laser pose in scan 0's frame
    problems = [Problem(the_map, laser, np.asarray(r, dtype=float), None) for r in ranges]
    if hasattr(m, "prepare"):
        m.prepare(problems[0])
    cands: list[Pose] = []
    for p, r in zip(problems, rel, strict=True):
        est = m.localize(p)
        if est.declined:
            continue
        for h in est.hypotheses or (est.pose,):
            if h.is_finite():
                _add(cands, h.compose(r.inverse()))
    if not cands:
        raise BagError(f"{where}: {matcher} found no pose for the first {len(problems)} scans; give the start "
                       "with --initial-pose X Y YAW or --initial-topic")
    scores = np.array([np.mean([m.score(p, c.compose(r)) for p, r in zip(problems, rel, strict=True)])
                       for c in cands])
    scores = np.where(np.isfinite(scores), scores, np.inf)
    best = int(np.argmin(scores))
    win = cands[best]
    far = [k for k, c in enumerate(cands) if c.distance_to(win) >= DISTINCT_M
           or abs(angdiff(c.theta, win.theta)) >= DISTINCT_RAD]
    other = min(far, key=lambda k: scores[k]) if far else None
    amb = other is not None and scores[other] < AMBIGUOUS_RATIO * scores[best]
    return FirstPose(win, "global-matcher", matcher, len(problems), float(scores[best]),
                     None if other is None else cands[other],
                     math.nan if other is None else float(scores[other]), bool(amb))


def _add(cands: list[Pose], p: Pose) -> None:
    """Add ``p`` unless a candidate within :data:`SAME_M` and :data:`SAME_RAD` is there."""
    if not any(c.distance_to(p) < SAME_M and abs(angdiff(c.theta, p.theta)) < SAME_RAD for c in cands):
        cands.append(p)
