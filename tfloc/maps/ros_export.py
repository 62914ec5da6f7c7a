"""A grid map written as map_server reads it (``.pgm`` + ``.yaml``): here, below the baselines,
because a baseline that runs as its own program (mrpt-pf) hands it the map so; ``tfloc.io.rosmap``
re-exports it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml
from PIL import Image

from .grid import GridMap


def write_ros_map(grid: GridMap, yaml_path: str | Path, image_suffix: str = ".pgm") -> Path:
    """Write ``grid`` as ``<stem>.pgm`` (or ``image_suffix``, e.g. ``.png``) + ``<stem>.yaml``
    (mode ``scale``, negate 0).

    Known cells keep their probability (to 1/255); unknown cells get a value between the
    thresholds, so reading the files back gives the same occupied and free cells."""
    path = Path(yaml_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    img = path.with_suffix(image_suffix)
    p = np.array(grid.occupancy, dtype=float)
    unknown = 0.5 * (grid.occupied_thresh + grid.free_thresh)
    v = np.round(255.0 * (1.0 - np.where(np.isnan(p), unknown, p))).astype(np.uint8)
    # keep the class of every cell despite rounding (compare as the reader does, in float32)
    occ_t, free_t = grid.occupied_thresh, grid.free_thresh
    back = lambda v: (255.0 - v.astype(np.float32)) / np.float32(255.0)  # noqa: E731
    v = np.where(grid.occupied & (back(v) <= occ_t), v - 1, v).astype(np.uint8)
    v = np.where(grid.free & (back(v) >= free_t), v + 1, v).astype(np.uint8)
    mid = ~grid.occupied & ~grid.free
    v = np.where(mid & (back(v) > occ_t), v + 1, v).astype(np.uint8)
    v = np.where(mid & (back(v) < free_t), v - 1, v).astype(np.uint8)
    Image.fromarray(np.flipud(v), mode="L").save(img)
    doc = {"image": img.name, "mode": "scale", "resolution": grid.resolution,
           "origin": [grid.origin[0], grid.origin[1], 0.0], "negate": 0,
           "occupied_thresh": grid.occupied_thresh, "free_thresh": grid.free_thresh}
    path.write_text(f"# tfloc GridMap {grid.name!r}: {grid.shape[1]} x {grid.shape[0]} cells\n"
                    + yaml.safe_dump(doc, sort_keys=False))
    return path
