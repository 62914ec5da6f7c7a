"""The AMCL port's particle filter and motion models piece by piece against nav2_amcl's C
(``pf.c``, ``pf_kdtree.c``, ``pf_pdf.c``, the motion models): KLD sample counts, resampling,
clusters, the kd-tree, the motion models' moments and drand48."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tfloc.baselines.amcl.motion_model.differential_motion_model import differential
from tfloc.baselines.amcl.motion_model.omni_motion_model import omni
from tfloc.baselines.amcl.pf import pf
from tfloc.baselines.amcl.pf import pf_kdtree as kd
from tfloc.baselines.amcl.pf.pf_pdf import drand48, new_stream


@pytest.mark.parametrize(("err", "z"), [(0.05, 0.99), (0.01, 3.0)])
def test_kld_sample_count_is_pf_resample_limit(err, z) -> None:
    """Fox's bound as pf.c writes it: n = ⌈(k − 1)/(2ε) · (1 − 2/(9(k − 1)) + √(2/(9(k − 1))) z)³⌉, clamped."""
    for k in (1, 2, 3, 10, 50, 120, 400, 3000):
        if k <= 1:
            want = 2000
        else:
            x = 1 - 2 / (9 * (k - 1)) + math.sqrt(2 / (9 * (k - 1))) * z
            want = min(max(math.ceil((k - 1) / (2 * err) * x ** 3), 500), 2000)
        assert pf.resample_limit(k, 500, 2000, err, z) == want, k
    assert pf.resample_limit(120, 500, 2000, 0.05, 0.99) == 1343  # pinned: 119/0.1 · 1.0409…³ = 1342.1


def test_resampling_stops_one_past_the_kld_limit() -> None:
    """pf_update_resample stops when the count exceeds the limit of the bins so far: a wide set
    keeps more particles than a narrow one, and the count is limit(k) + 1 (or max_samples)."""
    counts = []
    for sigma in (0.05, 0.5, 3.0):
        rng = new_stream(1)
        s = pf.init_gaussian(rng, np.array([5.0, 5.0, 0.0]), np.diag([sigma ** 2, sigma ** 2, 0.1]), 2000)
        out, *_ = pf.resample(rng, s, 0.0, 0.0, 500, 2000, 0.05, 0.99, np.zeros((0, 2), np.int64),
                              (0.0, 0.0, 0.05, 10, 10))
        assert out.count == min(2000, pf.resample_limit(out.bins, 500, 2000, 0.05, 0.99) + 1)
        assert np.allclose(out.weights, 1.0 / out.count)
        counts.append(out.count)
    assert counts[0] < counts[1] <= counts[2]


def test_heaviest_cluster_of_two_modes() -> None:
    """Two blobs 5 m apart: two clusters; the estimate is the heavier one's mean (Nav2's
    getMaxWeightHyp), not the whole set's."""
    rng = np.random.default_rng(0)
    a = np.column_stack((rng.normal(2.0, 0.1, 1200), rng.normal(2.0, 0.1, 1200), rng.normal(0.3, 0.05, 1200)))
    b = np.column_stack((rng.normal(7.0, 0.1, 800), rng.normal(6.0, 0.1, 800), rng.normal(-2.0, 0.05, 800)))
    poses = np.vstack((a, b))
    for w_b, heavy in ((1.0, a), (2.0, b)):
        w = np.r_[np.ones(1200), np.full(800, w_b)]
        s = pf.clustered(poses, w / w.sum())
        assert s.cluster_weight.size == 2
        k = s.heaviest()
        assert s.cluster_weight[k] == s.cluster_weight.max() and s.cluster_count[k] == len(heavy)
        assert np.allclose(s.cluster_mean[k, :2], heavy[:, :2].mean(axis=0), atol=1e-12)
        assert s.cluster_mean[k, 2] == pytest.approx(math.atan2(np.sin(heavy[:, 2]).sum(), np.cos(heavy[:, 2]).sum()))
        assert np.linalg.norm(s.mean[:2] - s.cluster_mean[k, :2]) > 1.0  # the set's mean lies between
    assert pf.clustered(poses[:1], np.zeros(1)).heaviest() == -1  # no positive weight: no pose


def test_kd_tree_bins_and_the_leaf_table() -> None:
    """Bins of 0.5 m, 0.5 m, 10° (heading not wrapped: θ and θ + 2π are two bins); one leaf per
    occupied bin, found alike by the tree (pf_kdtree_find_node) and the clustering's hash table."""
    rng = np.random.default_rng(1)
    poses = np.column_stack((rng.uniform(-3, 3, 3000), rng.uniform(-3, 3, 3000), rng.uniform(-4, 8, 3000)))
    tree = kd.alloc(3 * len(poses))
    for p in poses:
        kd.insert(tree, p, 1.0)
    keys = np.floor(poses / [0.5, 0.5, math.radians(10.0)]).astype(np.int64)
    assert tree[7][2] == len(np.unique(keys, axis=0))  # leaf_count: KLD's k
    table = kd.leaf_table(tree)
    for key in np.vstack((keys[:500], keys[:500] + [0, 0, 200])):  # present, and absent bins
        assert kd.find(tree, key) == kd.lookup(tree, table, *key)
    assert kd.find(tree, keys[0]) >= 0 and kd.find(tree, keys[0] + [0, 0, 200]) == -1


def moments(model: str, delta: tuple, n: int = 200_000, **alphas) -> tuple[np.ndarray, np.ndarray]:
    """Mean and variance of ``n`` particles moved from the origin (heading 0) by ``delta``."""
    poses = np.zeros((n, 3))
    a = {"alpha1": 0.0, "alpha2": 0.0, "alpha3": 0.0, "alpha4": 0.0, "alpha5": 0.0, **alphas}
    d = np.array(delta, dtype=float)
    if model == "omni":
        omni(new_stream(7), poses, d, d, a["alpha1"], a["alpha2"], a["alpha3"], a["alpha4"], a["alpha5"])
    else:
        differential(new_stream(7), poses, d, d, a["alpha1"], a["alpha2"], a["alpha3"], a["alpha4"])
    return poses.mean(axis=0), poses.var(axis=0)


def test_differential_motion_model_moments() -> None:
    """1 m forward: rot1, rot2 ~ N(0, α2), trans ~ N(1, α3) (Probabilistic Robotics Table 5.6):
    E x = e^(−α2/2), var x = (1 + α3)(1 + e^(−2α2))/2 − e^(−α2), var y = (1 + α3)(1 − e^(−2α2))/2,
    var θ = 2 α2; backward the same, mirrored (Nav2's symmetric noise); a turn in place of 0.5 rad:
    θ ~ N(0.5, α1/4), x ~ N(0, α4/4)."""
    a2, a3 = 0.05, 0.1
    mean, var = moments("differential", (1.0, 0.0, 0.0), alpha2=a2, alpha3=a3)
    want_var = np.array([(1 + a3) * (1 + math.exp(-2 * a2)) / 2 - math.exp(-a2), (1 + a3) * (1 - math.exp(-2 * a2)) / 2,
                         2 * a2])
    assert np.allclose(mean, [math.exp(-a2 / 2), 0.0, 0.0], atol=5 * np.sqrt(want_var / 200_000))
    assert np.allclose(var, want_var, rtol=0.02)
    back, back_var = moments("differential", (-1.0, 0.0, 0.0), alpha2=a2, alpha3=a3)
    assert back[0] == pytest.approx(-math.exp(-a2 / 2), abs=3e-3) and np.allclose(back_var[:2], want_var[:2], rtol=0.02)
    mean, var = moments("differential", (0.0, 0.0, 0.5), alpha1=0.2, alpha4=0.1)
    assert np.allclose(mean, [0.0, 0.0, 0.5], atol=3e-3)
    assert np.allclose(var, [0.1 / 4, 0.0, 0.2 / 4], rtol=0.02, atol=1e-12)


def test_omni_motion_model_moments() -> None:
    """1 m forward: trans ~ N(1, α3), strafe ~ N(0, α5), θ ~ N(0, α2)."""
    mean, var = moments("omni", (1.0, 0.0, 0.0), alpha2=0.04, alpha3=0.1, alpha5=0.2)
    assert np.allclose(mean, [1.0, 0.0, 0.0], atol=3e-3)
    assert np.allclose(var, [0.1, 0.2, 0.04], rtol=0.02)


def test_drand48_is_the_c_librarys() -> None:
    """srand48(0) then drand48(): the first draws of glibc's (and POSIX's) stream."""
    state = new_stream(0)
    x0 = (0 << 16) | 0x330E
    x1 = (0x5DEECE66D * x0 + 0xB) % 2 ** 48
    assert drand48(state) == x1 / 2 ** 48 == pytest.approx(0.170828036106)


# -- the tracker ----------------------------------------------------------------------------------
