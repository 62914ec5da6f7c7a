"""The map_server reading rules, pinned on hand-made images (ROS 1 map_server image_loader.cpp:
shade = mean of the channels, alpha averaged in only in trinary mode, p = (255 − shade) / 255,
negate flips it, p > occupied_thresh occupied, p < free_thresh free, between: unknown (trinary)
or grey (scale) unless fully transparent)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from tfloc.io.rosmap import read_ros_map

OCC, FREE = 0.65, 0.196


def _map(tmp_path: Path, pixels: np.ndarray, mode: str | None, negate: int = 0, name: str = "m"):
    """Write ``pixels`` (one row, uint8, image mode from its shape) as a PNG map and read it."""
    img_mode = {2: "L", 3: {2: "LA", 3: "RGB", 4: "RGBA"}}[pixels.ndim]
    if pixels.ndim == 3:
        img_mode = img_mode[pixels.shape[-1]]
    Image.fromarray(pixels, mode=img_mode).save(tmp_path / f"{name}.png")
    text = (f"image: {name}.png\nresolution: 1\norigin: [0, 0, 0]\nnegate: {negate}\n"
            f"occupied_thresh: {OCC}\nfree_thresh: {FREE}\n" + (f"mode: {mode}\n" if mode else ""))
    (tmp_path / f"{name}.yaml").write_text(text)
    return read_ros_map(tmp_path / f"{name}.yaml")


# grey levels: 0 black (p = 1), 80 (p = 0.686 > 0.65), 100 (p = 0.608: between), 210 (p = 0.176 < 0.196), 254, 255
GREYS = np.array([[0, 80, 100, 180, 210, 254, 255]], dtype=np.uint8)


def test_trinary_is_the_default_and_between_is_unknown(tmp_path: Path) -> None:
    for mode in (None, "trinary"):
        g = _map(tmp_path, GREYS, mode)
        assert g.occupied[0].tolist() == [True, True, False, False, False, False, False]
        assert g.free[0].tolist() == [False, False, False, False, True, True, True]
        assert np.isnan(g.occupancy[0, 2:4]).all()
        np.testing.assert_allclose(g.occupancy[0, [0, 1, 4]], (255 - GREYS[0, [0, 1, 4]]) / 255, atol=1e-6)


def test_scale_keeps_grey_probabilities_between_the_thresholds(tmp_path: Path) -> None:
    g = _map(tmp_path, GREYS, "scale")
    assert g.occupied[0].tolist() == [True, True, False, False, False, False, False]
    assert g.free[0].tolist() == [False, False, False, False, True, True, True]
    np.testing.assert_allclose(g.occupancy[0], (255 - GREYS[0]) / 255, atol=1e-6)  # grey kept, not NaN


def test_negate_flips_the_shade(tmp_path: Path) -> None:
    g = _map(tmp_path, GREYS, "trinary", negate=1)  # p = shade / 255: white is occupied
    assert g.occupied[0].tolist() == [False, False, False, True, True, True, True]
    assert g.free[0].tolist() == [True, False, False, False, False, False, False]


def test_colour_channels_are_averaged_not_weighted(tmp_path: Path) -> None:
    # mean of (255, 0, 0) = 85 → p 0.667 occupied; (0, 255, 255) and (255, 255, 0) = 170 → p 0.333
    # unknown (a luminance weighting would make the yellow 226 → p 0.11: free)
    rgb = np.array([[[255, 0, 0], [0, 255, 255], [255, 255, 0], [254, 254, 254]]], dtype=np.uint8)
    g = _map(tmp_path, rgb, "trinary")
    assert g.occupied[0].tolist() == [True, False, False, False]
    assert g.free[0].tolist() == [False, False, False, True]


def test_alpha_is_averaged_in_trinary_and_marks_unknown_in_scale(tmp_path: Path) -> None:
    # grey 100 (p = 0.608, between) and 254 (free), each opaque and fully transparent
    la = np.array([[[100, 255], [100, 0], [254, 255], [254, 0], [0, 0]]], dtype=np.uint8)
    t = _map(tmp_path, la, "trinary", name="t")
    # trinary: shade = (grey + alpha) / 2: 177.5 (p 0.30 unknown), 50 (p 0.80 occupied),
    # 254.5 (free), 127 (p 0.50 unknown), 0 (occupied)
    assert t.occupied[0].tolist() == [False, True, False, False, True]
    assert t.free[0].tolist() == [False, False, True, False, False]
    s = _map(tmp_path, la, "scale", name="s")
    # scale: shade = grey; a transparent grey pixel is unknown, thresholds still decide the rest
    assert s.occupied[0].tolist() == [False, False, False, False, True]
    assert s.free[0].tolist() == [False, False, True, True, False]
    assert not np.isnan(s.occupancy[0, 0]) and np.isnan(s.occupancy[0, 1])
