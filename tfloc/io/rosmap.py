"""ROS map_server maps (YAML + PGM/PNG image) ↔ :class:`~tfloc.maps.grid.GridMap`.

YAML keys: ``image`` (path relative to the YAML), ``resolution`` (m/cell), ``origin`` ``[x, y, yaw]``
(pose of the lower-left pixel, yaw must be 0), ``occupied_thresh``, ``free_thresh``, ``negate``
(0/1) and optionally ``mode`` (``trinary``, the default, or ``scale``). The reader follows ROS 1
map_server's ``image_loader.cpp`` (nav2's ``map_io.cpp`` agrees on everything tested here): a
pixel's shade is the mean of its channels (in ``trinary`` mode the alpha channel is averaged in
too; in ``scale`` mode it is not), ``negate`` flips the shade, ``p = (255 − shade) / 255``;
``p > occupied_thresh`` is occupied, ``p < free_thresh`` free; anything between is unknown in
``trinary`` mode and keeps its grey probability ``p`` in ``scale`` mode (map_server serves it as
a value in 0–99), unless the pixel is fully transparent (alpha 0: unknown). Grey cells are neither
occupied nor free, as in ROS. Image row 0 is the top (largest y).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml
from PIL import Image, UnidentifiedImageError

from tfloc.errors import MapFormatError
from tfloc.maps.grid import GridMap
from tfloc.maps.ros_export import write_ros_map  # noqa: F401 - the writer lives with the grid (baselines use it)

from .text import parse_text


def _finite(v: object) -> bool:
    """A number (not a bool) that is a finite float (an integer too large for a float is not)."""
    try:
        return not isinstance(v, bool) and isinstance(v, int | float) and math.isfinite(float(v))
    except OverflowError:
        return False


def _num(doc: dict, key: str, path: Path, default: float | None = None) -> float:
    if key not in doc:
        if default is None:
            raise MapFormatError(f"{path}: missing key {key!r}")
        return default
    v = doc[key]
    if not _finite(v):
        raise MapFormatError(f"{path}: key {key!r} must be a finite number, got {v!r:.40}")
    return float(v)


def _shade(im: Image.Image, mode: str) -> tuple[np.ndarray, np.ndarray]:
    """map_server's per-pixel shade (mean of the channels, 0–255, float32) and alpha (0–255).

    In ``trinary`` mode an alpha channel is averaged in with the colours (map_server keeps this
    for old maps); in ``scale`` mode it is left out and returned as the alpha. Palette images are
    read as their colours, 1-bit and 16-bit images as grey levels."""
    if im.mode == "P":
        im = im.convert("RGBA" if "transparency" in im.info else "RGB")
    elif im.mode in ("1", "I", "I;16"):
        im = im.convert("L")
    a = np.asarray(im, dtype=np.float32)
    if a.ndim == 2:
        return a, np.full(a.shape, 255.0, dtype=np.float32)
    has_alpha = im.mode in ("LA", "RGBA")
    alpha = a[..., -1] if has_alpha else np.full(a.shape[:2], 255.0, dtype=np.float32)
    colours = a[..., :-1] if has_alpha and mode == "scale" else a
    return colours.sum(axis=-1) / np.float32(colours.shape[-1]), alpha


def read_ros_map(yaml_path: str | Path) -> GridMap:
    """Read a map_server YAML and its image into a GridMap (unknown pixels become NaN)."""
    path = Path(yaml_path)
    doc = parse_text(path, MapFormatError, "map file", yaml.safe_load, yaml.YAMLError, "YAML")
    if not isinstance(doc, dict):
        raise MapFormatError(f"{path}: expected a mapping of map_server keys")
    if not isinstance(doc.get("image"), str):
        raise MapFormatError(f"{path}: missing or non-string key 'image'")
    res = _num(doc, "resolution", path)
    if res <= 0:
        raise MapFormatError(f"{path}: resolution must be a positive number of metres per cell, got {res}")
    occ_t = _num(doc, "occupied_thresh", path, 0.65)
    free_t = _num(doc, "free_thresh", path, 0.196)
    negate = _num(doc, "negate", path, 0.0)
    origin = doc.get("origin")
    if (not isinstance(origin, list) or len(origin) != 3
            or not all(_finite(v) for v in origin)):
        raise MapFormatError(f"{path}: 'origin' must be [x, y, yaw] numbers, got {origin!r:.80}")
    if origin[2] != 0:
        raise MapFormatError(f"{path}: rotated maps (origin yaw {origin[2]}) are not supported")
    mode = doc.get("mode", "trinary")
    if mode not in ("trinary", "scale"):
        raise MapFormatError(f"{path}: mode {mode!r} is not supported (trinary or scale)")
    img_path = path.parent / doc["image"]
    try:
        with Image.open(img_path) as im:
            im.load()
            if im.mode not in ("L", "LA", "RGB", "RGBA", "I", "I;16", "P", "1"):
                raise MapFormatError(f"{img_path}: unsupported image mode {im.mode} (the map image of {path})")
            shade, alpha = _shade(im, mode)
    except FileNotFoundError:
        raise MapFormatError(f"{path}: image {doc['image']!r} not found next to the YAML") from None
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError) as exc:
        why = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        raise MapFormatError(f"{img_path}: cannot read the map image of {path} ({why})") from None
    p = shade / np.float32(255.0) if negate else (np.float32(255.0) - shade) / np.float32(255.0)
    known = (p > occ_t) | (p < free_t)
    if mode == "scale":
        known |= alpha > 0
    occ = np.where(known, p, np.nan).astype(np.float32)
    try:
        return GridMap(np.flipud(occ), res, (float(origin[0]), float(origin[1])), occ_t, free_t,
                       name=path.stem)
    except MapFormatError as exc:
        raise MapFormatError(f"{path}: {str(exc).removeprefix(path.stem + ': ')}") from None


#: map_saver's pixel values: occupied, free, unknown.
SAVER_PIXELS = (0, 254, 205)
#: cartographer_ros's pixel for a never-observed cell (its canvas's 0.5 grey).
CARTO_UNKNOWN_PIXEL = 128


def write_exported_map(grid: GridMap, yaml_path: str | Path, exporter: str, image_suffix: str = ".png") -> Path:
    """Write ``grid`` the way a ROS mapping tool exports a map: image + YAML without ``mode``
    (map_server reads it as ``trinary``), the grid's thresholds, negate 0.

    ``exporter`` = ``"map_saver"`` (ROS map_saver, e.g. of a gmapping map): occupied cells 0,
    free 254, the rest 205; ``"cartographer"`` (cartographer_ros's pbstream_to_ros_map): every
    observed cell its grey level ``round(255 · (1 − p))``, unobserved cells 128."""
    path = Path(yaml_path)
    path.parent.mkdir(parents=True, exist_ok=True)
    img = path.with_suffix(image_suffix)
    if exporter == "map_saver":
        occ_v, free_v, unk_v = SAVER_PIXELS
        v = np.where(grid.occupied, occ_v, np.where(grid.free, free_v, unk_v))
    elif exporter == "cartographer":
        p = np.array(grid.occupancy, dtype=float)
        v = np.where(np.isnan(p), CARTO_UNKNOWN_PIXEL, np.round(255.0 * (1.0 - np.nan_to_num(p))))
    else:
        raise ValueError(f"unknown exporter {exporter!r} (map_saver or cartographer)")
    Image.fromarray(np.flipud(v.astype(np.uint8)), mode="L").save(img)
    doc = {"image": img.name, "resolution": grid.resolution,
           "origin": [grid.origin[0], grid.origin[1], 0.0], "negate": 0,
           "occupied_thresh": grid.occupied_thresh, "free_thresh": grid.free_thresh}
    path.write_text(f"# tfloc GridMap {grid.name!r} as {exporter} exports it: "
                    f"{grid.shape[1]} x {grid.shape[0]} cells\n" + yaml.safe_dump(doc, sort_keys=False))
    return path
