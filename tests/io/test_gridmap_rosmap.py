"""ROS map_server YAML + PGM: write → read round trip, reading maps written by others, strict errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import tfloc
from tfloc.core.laser import LaserSpec
from tfloc.core.pose import Pose
from tfloc.errors import MapFormatError
from tfloc.io.rosmap import read_ros_map, write_ros_map
from tfloc.maps import GridMap


def _random_grid(seed: int = 0) -> GridMap:
    rng = np.random.default_rng(seed)
    occ = rng.uniform(0, 1, size=(37, 53)).astype(np.float32)
    occ[rng.uniform(size=occ.shape) < 0.2] = np.nan
    occ[5, :] = 1.0
    occ[:, 7] = 0.0
    occ[10, 10] = 0.25  # exactly on a threshold
    return GridMap(occ, 0.05, (-1.234, 2.5), occupied_thresh=0.25, free_thresh=0.1, name="rnd")


def test_round_trip_keeps_cells_geometry_and_rays(tmp_path: Path) -> None:
    g = _random_grid()
    path = write_ros_map(g, tmp_path / "m.yaml")
    assert (tmp_path / "m.pgm").read_bytes()[:2] == b"P5"
    h = tfloc.load_map(path)
    assert isinstance(h, GridMap)
    assert h.shape == g.shape and h.resolution == g.resolution and h.origin == g.origin
    assert (h.occupied_thresh, h.free_thresh) == (0.25, 0.1)
    np.testing.assert_array_equal(h.occupied, g.occupied)
    np.testing.assert_array_equal(h.free, g.free)
    known = h.occupied | h.free
    np.testing.assert_allclose(h.occupancy[known], g.occupancy[known], atol=1.5 / 255)
    laser = LaserSpec.from_degrees(5, 180, 1)
    pose = Pose(-1.234 + 1.3, 2.5 + 0.9, 0.4)
    np.testing.assert_array_equal(h.raycast(pose, laser), g.raycast(pose, laser))
    # and again: what was read is written and read back unchanged
    h2 = read_ros_map(write_ros_map(h, tmp_path / "again" / "m.yaml"))
    np.testing.assert_array_equal(h2.occupancy, h.occupancy)


def test_reads_a_map_saver_style_trinary_map(tmp_path: Path) -> None:
    """map_saver writes 0 = occupied, 254 = free, 205 = unknown, image row 0 = top."""
    img = np.full((4, 6), 205, dtype=np.uint8)
    img[0, :] = 0      # top row: occupied (largest y)
    img[1:, 1:5] = 254
    Image.fromarray(img).save(tmp_path / "map.pgm")
    (tmp_path / "map.yaml").write_text(
        "image: map.pgm\nresolution: 0.5\norigin: [-1.0, 2.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    g = read_ros_map(tmp_path / "map.yaml")
    assert g.shape == (4, 6) and g.occupied[3].all() and not g.occupied[:3].any()
    assert g.free[:3, 1:5].all() and np.isnan(g.occupancy[0, 0])
    assert g.is_free(np.array([[-1.0 + 0.75, 2.25]]))[0]          # cell (1, 0): free
    assert not g.is_free(np.array([[-1.0 + 0.25, 2.25]]))[0]      # unknown
    r = g.raycast(Pose(0.25, 2.25, np.pi / 2), LaserSpec.from_degrees(10, 2, 1))
    assert r[1] == pytest.approx(1.5)  # to the middle of the top row (y 3.5-4.0) from y = 2.25


def test_negate(tmp_path: Path) -> None:
    img = np.array([[255, 0]], dtype=np.uint8)
    Image.fromarray(img).save(tmp_path / "n.pgm")
    (tmp_path / "n.yaml").write_text("image: n.pgm\nresolution: 1\norigin: [0, 0, 0]\nnegate: 1\n"
                                     "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    g = read_ros_map(tmp_path / "n.yaml")
    assert g.occupied[0, 0] and g.free[0, 1]


@pytest.mark.parametrize("yaml_text, message", [
    ("image: m.pgm\norigin: [0, 0, 0]\n", "missing key 'resolution'"),
    ("image: m.pgm\nresolution: fine\norigin: [0, 0, 0]\n", "'resolution' must be a finite number"),
    ("image: m.pgm\nresolution: 0.05\norigin: [0, 0]\n", "'origin' must be"),
    ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0.3]\n", "rotated maps"),
    ("resolution: 0.05\norigin: [0, 0, 0]\n", "'image'"),
    ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nmode: raw\n", "mode 'raw'"),
    ("image: absent.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n", "not found"),
    ("image: m.pgm\nresolution: -1\norigin: [0, 0, 0]\n", "resolution must be a positive"),
    ("image: [m.pgm\n", "not valid YAML"),
])
def test_bad_yaml_is_named(tmp_path: Path, yaml_text: str, message: str) -> None:
    write_ros_map(_random_grid(), tmp_path / "m.yaml")
    (tmp_path / "bad.yaml").write_text(yaml_text)
    with pytest.raises(MapFormatError, match=message) as exc:
        read_ros_map(tmp_path / "bad.yaml")
    assert "bad.yaml" in str(exc.value) or "m.pgm" in str(exc.value) or "absent" in str(exc.value)


def test_truncated_or_garbled_image(tmp_path: Path) -> None:
    write_ros_map(_random_grid(), tmp_path / "m.yaml")
    pgm = tmp_path / "m.pgm"
    data = pgm.read_bytes()
    pgm.write_bytes(data[: len(data) // 2])
    with pytest.raises(MapFormatError, match="m.pgm: cannot read the map image of "):
        read_ros_map(tmp_path / "m.yaml")
    pgm.write_bytes(b"not an image at all")
    with pytest.raises(MapFormatError, match="m.pgm: cannot read the map image of "):
        read_ros_map(tmp_path / "m.yaml")


def test_gridmap_validates_its_fields() -> None:
    with pytest.raises(MapFormatError, match="2-D"):
        GridMap(np.zeros(5), 0.05)
    with pytest.raises(MapFormatError, match=r"\[0, 1\]"):
        GridMap(np.full((2, 2), 2.0), 0.05)
    with pytest.raises(MapFormatError, match="free_thresh"):
        GridMap(np.zeros((2, 2)), 0.05, occupied_thresh=0.1, free_thresh=0.5)
