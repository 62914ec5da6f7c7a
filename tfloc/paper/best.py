"""``tf-best``: the paper's method with the best-measured reading of each ambiguity of its text.

The same method as ``tf`` (:mod:`tfloc.paper.matcher`: ShortStraw corners, turning functions
matched over starting vertex and rotation, Alg. 5's simplex with seven orientations per vertex,
outer re-simulations), no extra stage. Only where the text is ambiguous does it read otherwise
than ``tf``, each reading the best measured on the reading study's development split (the
first 40 scans of each office-pool group; ``results/tf-readings/README.md`` has the numbers):

* **Err is the area between the graphs** (``err_norm="l1"``): Sec. 4.3, "The area between the
  two graphs is then computed. Rectangles are created between two graphs because they are in the
  form of histograms." (Eq. 13 squares the heights instead.) The largest gain of the study.
* **S = 0.1 m** (``spacing``): Alg. 1's "S ← 1" has no unit; the straws and Is-Line test of
  Algs. 2 and 3 only mean something when the resampled points are dense enough to follow walls.
* **w = 3** (``window``): the paper's "ω=1" counts resampled points; at S = 0.1 m one point is
  0.2 m of noisy scan, and Wolin et al.'s ShortStraw uses 3.
* **Orientation step 2.5°**: "the angle of each of these three vertices is examined locally in
  seven orientations" gives no step.
* **Simplex 2 m**: "The maximum value of the robot position difference should be covered by this
  interval." (vertices up to 2 m from the initial guess).
* **Heading change clamped to ±15°** (``heading_clamp``): "examined locally", and 15° is the
  protocol's largest initial angle offset; unbounded, the histogram's rotation offset swings the
  heading by up to 180° at wrong positions.
* **Keep the best answer** (``keep_best``): Alg. 5's "B ← find the point among B, NB and W with
  minimum error", read across the outer iterations too.
"""

from __future__ import annotations

import math

from .matcher import TfConfig, TurningFunctionMatcher

BEST = TfConfig(err_norm="l1", spacing=0.1, window=3, orientation_step=math.radians(2.5),
                simplex_size=2.0, heading_clamp=math.radians(15.0), keep_best=True)


class TurningFunctionBestMatcher(TurningFunctionMatcher):
    """``tf-best``: :class:`~tfloc.paper.matcher.TurningFunctionMatcher` with the readings of :data:`BEST`."""

    name = "tf-best"

    def __init__(self, config: TfConfig | None = None, **overrides) -> None:
        super().__init__(config or BEST, **overrides)


REGISTRY = {"tf-best": {"class": "TurningFunctionBestMatcher", "docs": "single-scan.md", "summary": (
    "the paper's method with the best-measured reading of each ambiguity of its text (Err the"
    " area between the graphs, S = 0.1 m, w = 3, orientation step 2.5°, simplex 2 m, heading "
    "change clamped to ±15°, the best answer kept), each chosen on the reading study's "
    "development split; no extra stage")}}
