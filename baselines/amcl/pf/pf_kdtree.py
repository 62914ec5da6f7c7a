# SPDX-License-Identifier: LGPL-2.1-or-later (a translation of nav2_amcl; see docs/baselines/amcl.md)
"""Translates ``nav2_amcl/src/pf/pf_kdtree.c``: Nav2's pose histogram, compiled with numba.

A pose falls in the bin ``floor((x, y, θ) / (0.5 m, 0.5 m, 10°))`` (θ as the particle carries it,
not wrapped). The bins with samples are the leaves of a kd-tree, built insert by insert exactly as
``pf_kdtree_insert_node`` builds it (a leaf met by another key splits on the axis of the largest
key difference at the mean of the two keys), because the tree's node order decides the cluster
labels. ``leaf_count`` is KLD sampling's ``k``. ``cluster`` labels the connected components of the
occupied bins (26-neighbourhood: ``pf_kdtree_cluster``), seeds taken from the last leaf created
backwards, labels 0, 1, … in that order. Departure: clustering finds a bin's leaf in a hash table
of the leaves (:func:`leaf_table`) instead of descending the tree (:func:`find`): the same leaf,
in constant time (a spread cloud has ~2000 bins × 27 neighbours).

A tree is a tuple of arrays (``alloc``): ``keys (M, 3)`` int64, ``leaf (M,)`` bool, ``pivot_dim``,
``pivot_value``, ``child (M, 2)``, ``value`` (summed weights), ``cluster`` and ``meta`` = ``[root,
node_count, leaf_count]``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: bin size: x, y (m), heading (rad), as pf_kdtree_alloc
SIZE_XY = 0.50
SIZE_A = 10 * math.pi / 180


@njit(cache=True, nogil=True)
def alloc(max_size: int):  # noqa: ANN201 - a tuple of arrays (module notes)
    """An empty tree of at most ``max_size`` nodes (Nav2 allocates ``3 × max_samples``)."""
    keys = np.zeros((max_size, 3), dtype=np.int64)
    leaf = np.zeros(max_size, dtype=np.bool_)
    pivot_dim = np.zeros(max_size, dtype=np.int64)
    pivot_value = np.zeros(max_size)
    child = np.full((max_size, 2), -1, dtype=np.int64)
    value = np.zeros(max_size)
    cluster = np.full(max_size, -1, dtype=np.int64)
    meta = np.array([-1, 0, 0], dtype=np.int64)
    return keys, leaf, pivot_dim, pivot_value, child, value, cluster, meta


@njit(cache=True, nogil=True)
def key_of(pose: np.ndarray, key: np.ndarray) -> None:
    """The bin of ``pose`` (``floor(pose / size)``), into ``key``."""
    key[0] = int(math.floor(pose[0] / SIZE_XY))
    key[1] = int(math.floor(pose[1] / SIZE_XY))
    key[2] = int(math.floor(pose[2] / SIZE_A))


@njit(cache=True, nogil=True)
def _new_leaf(tree, key: np.ndarray, value: float) -> int:
    keys, leaf, _, _, child, values, cluster, meta = tree
    node = meta[1]
    meta[1] += 1
    keys[node, 0], keys[node, 1], keys[node, 2] = key[0], key[1], key[2]
    leaf[node] = True
    child[node, 0] = -1
    child[node, 1] = -1
    values[node] = value
    cluster[node] = -1
    meta[2] += 1
    return node


@njit(cache=True, nogil=True)
def insert(tree, pose: np.ndarray, value: float) -> None:
    """``pf_kdtree_insert``: add ``value`` to the bin of ``pose``."""
    keys, leaf, pivot_dim, pivot_value, child, values, _, meta = tree
    key = np.empty(3, dtype=np.int64)
    key_of(pose, key)
    if meta[0] < 0:
        meta[0] = _new_leaf(tree, key, value)
        return
    node = meta[0]
    while not leaf[node]:
        d = pivot_dim[node]
        node = child[node, 0] if key[d] < pivot_value[node] else child[node, 1]
    if keys[node, 0] == key[0] and keys[node, 1] == key[1] and keys[node, 2] == key[2]:
        values[node] += value
        return
    max_split = 0
    dim = -1
    for i in range(3):
        split = abs(key[i] - keys[node, i])
        if split > max_split:
            max_split = split
            dim = i
    pivot_dim[node] = dim
    pivot_value[node] = (key[dim] + keys[node, dim]) / 2.0
    old = keys[node].copy()
    if key[dim] < pivot_value[node]:
        child[node, 0] = _new_leaf(tree, key, value)
        child[node, 1] = _new_leaf(tree, old, values[node])
    else:
        child[node, 0] = _new_leaf(tree, old, values[node])
        child[node, 1] = _new_leaf(tree, key, value)
    leaf[node] = False
    meta[2] -= 1


@njit(cache=True, nogil=True)
def find(tree, key: np.ndarray) -> int:
    """``pf_kdtree_find_node``: the leaf of bin ``key``, or -1."""
    keys, leaf, pivot_dim, pivot_value, child, _, _, meta = tree
    node = meta[0]
    if node < 0:
        return -1
    while not leaf[node]:
        d = pivot_dim[node]
        node = child[node, 0] if key[d] < pivot_value[node] else child[node, 1]
    if keys[node, 0] == key[0] and keys[node, 1] == key[1] and keys[node, 2] == key[2]:
        return node
    return -1


@njit(cache=True, nogil=True)
def _slot(k0: int, k1: int, k2: int, mask: int) -> int:
    return ((k0 * 73856093) ^ (k1 * 19349663) ^ (k2 * 83492791)) & mask


@njit(cache=True, nogil=True)
def leaf_table(tree) -> np.ndarray:
    """An open-addressing hash table of the leaves' keys (node index, -1 = empty): the same leaf
    ``find`` gives, found in constant time (clustering asks 27 neighbours of every bin)."""
    keys, leaf, _, _, _, _, _, meta = tree
    size = 16
    while size < 4 * meta[2]:
        size *= 2
    table = np.full(size, -1, dtype=np.int64)
    mask = size - 1
    for node in range(meta[1]):
        if leaf[node]:
            h = _slot(keys[node, 0], keys[node, 1], keys[node, 2], mask)
            while table[h] >= 0:
                h = (h + 1) & mask
            table[h] = node
    return table


@njit(cache=True, nogil=True)
def lookup(tree, table: np.ndarray, k0: int, k1: int, k2: int) -> int:
    """The leaf of bin ``(k0, k1, k2)`` in ``table`` (:func:`leaf_table`), or -1."""
    keys = tree[0]
    mask = table.size - 1
    h = _slot(k0, k1, k2, mask)
    while table[h] >= 0:
        node = table[h]
        if keys[node, 0] == k0 and keys[node, 1] == k1 and keys[node, 2] == k2:
            return node
        h = (h + 1) & mask
    return -1


@njit(cache=True, nogil=True)
def cluster(tree, table: np.ndarray) -> int:
    """``pf_kdtree_cluster``: label the connected components of the leaves; their number."""
    keys, leaf, _, _, _, _, labels, meta = tree
    n_nodes = meta[1]
    queue = np.empty(n_nodes, dtype=np.int64)
    count = 0
    for i in range(n_nodes):
        if leaf[i]:
            labels[i] = -1
            queue[count] = i
            count += 1
    stack = np.empty(n_nodes, dtype=np.int64)
    n_clusters = 0
    while count > 0:
        count -= 1
        seed = queue[count]
        if labels[seed] >= 0:
            continue
        labels[seed] = n_clusters
        top = 0
        stack[top] = seed
        top += 1
        while top > 0:  # the labels do not depend on the visiting order, only on the seeds'
            top -= 1
            node = stack[top]
            for i in range(27):
                other = lookup(tree, table, keys[node, 0] + (i // 9) - 1, keys[node, 1] + ((i % 9) // 3) - 1,
                               keys[node, 2] + ((i % 9) % 3) - 1)
                if other < 0 or labels[other] >= 0:
                    continue
                labels[other] = n_clusters
                stack[top] = other
                top += 1
        n_clusters += 1
    return n_clusters


@njit(cache=True, nogil=True)
def cluster_of(tree, table: np.ndarray, pose: np.ndarray) -> int:
    """``pf_kdtree_get_cluster``: the label of the bin of ``pose`` (-1 if the bin is empty)."""
    node = lookup(tree, table, int(math.floor(pose[0] / SIZE_XY)), int(math.floor(pose[1] / SIZE_XY)),
                  int(math.floor(pose[2] / SIZE_A)))
    return -1 if node < 0 else tree[6][node]
