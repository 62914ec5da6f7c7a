"""jsonable gives what a JSON round trip of run.json gives (dumps with default=str, then loads)."""

from __future__ import annotations

import enum
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tfloc.core.jsonable import jsonable


class Kind(enum.StrEnum):
    A = "a"


@dataclass(frozen=True)
class Cfg:
    path: Path
    sizes: tuple[int, ...]
    steps: dict
    ratio: float = math.inf


def test_jsonable_is_the_json_round_trip():
    values = [
        Cfg(Path("maps/x.geojson"), (1, 2), {"a": (0.5, None), 3: [True, Kind.A]}),
        {"n": np.int64(3), "f": np.float64(0.25), "nan": math.nan, "inf": -math.inf, 1.5: "k", True: 1, None: 2},
        [(), {}, "", 0, False, Path("/")],
    ]
    for v in values:
        expected = json.loads(json.dumps(v if not isinstance(v, Cfg) else v.__dict__, default=str))
        got = jsonable(v)
        assert json.dumps(got, sort_keys=True, default=repr) == json.dumps(expected, sort_keys=True, default=repr)
        assert got == expected or any(isinstance(x, float) and math.isnan(x) for x in got.values())
    assert jsonable(Cfg(Path("p"), (1,), {}))["sizes"] == [1] and jsonable(Kind.A) == "a"
    assert type(jsonable(Kind.A)) is str and type(jsonable(np.float64(1.0))) is float
