"""The first-jump pictures of the tracking report (tfloc.report.jumps)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from tfloc.maps.vector import VectorMap
from tfloc.report.jumps import EVENT_GAP, fig_jumps, first_jumps


def _rows(matcher: str, jump_at: list[int], n: int = 60) -> pd.DataFrame:
    x = np.linspace(0.0, 6.0, n)
    est = np.column_stack([x, np.zeros(n)])
    init = est.copy()
    for i in jump_at:
        est[i, 1] = 2.0                                   # 2 m from its prediction
    return pd.DataFrame({"matcher": matcher, "scan_id": [f"s{i:03d}" for i in range(n)],
                         "est_x": est[:, 0], "est_y": est[:, 1], "est_theta": 0.0,
                         "init_x": init[:, 0], "init_y": init[:, 1], "init_theta": 0.0,
                         "true_x": x, "true_y": 0.0, "true_theta": 0.0})


def test_first_jumps_are_distinct_events_per_matcher() -> None:
    rows = pd.concat([_rows("a", [5, 6, 7, 5 + EVENT_GAP, 40, 50]), _rows("b", []),
                      _rows("c", [30])])
    assert first_jumps(rows) == [("a", 5), ("a", 5 + EVENT_GAP), ("a", 40), ("c", 30)]
    assert first_jumps(rows, per_matcher=1) == [("a", 5), ("c", 30)]


def test_a_jump_below_a_metre_is_none() -> None:
    rows = _rows("a", [])
    rows.loc[10, "est_y"] = 0.9
    assert first_jumps(rows) == []


def test_the_figure_is_drawn_only_when_there_are_jumps(tmp_path) -> None:
    room = VectorMap.from_segments(np.array([[-1, -3, 8, -3], [8, -3, 8, 3], [8, 3, -1, 3], [-1, 3, -1, -3]],
                                            dtype=float))
    assert fig_jumps("seq", room, _rows("a", []), tmp_path / "none.png") is None
    path = fig_jumps("seq", room, _rows("a", [20]), tmp_path / "j.png")
    assert path is not None and path.stat().st_size > 1000
