"""Edges, adjacency and connected parts of triangle meshes.

``F`` is an (m, 3) int array of triangles over ``n`` vertices; sparse
results are ``scipy.sparse.csr_matrix``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components


def triangle_edges(F: np.ndarray) -> np.ndarray:
    """(3m, 2) int: the three edges of every triangle, smaller index first
    (an edge shared by k triangles appears k times)."""
    all_edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    all_edges.sort(axis=1)
    return all_edges


def _edge_keys(F: np.ndarray) -> tuple[np.ndarray, int]:
    """One int64 key per triangle edge (``smaller * width + larger``, an
    edge shared by k triangles k times) and the ``width``. Keys sort as the
    edges' rows do, and 1-D sorting is many times faster than
    ``unique(axis=0)``, which sorts structured rows."""
    pairs = triangle_edges(np.asarray(F, dtype=np.int64))
    width = int(pairs.max()) + 1 if len(pairs) else 1
    return pairs[:, 0] * width + pairs[:, 1], width


def edges(F: np.ndarray) -> np.ndarray:
    """(e, 2) int64 unique undirected edges, smaller index first, sorted."""
    keys, width = _edge_keys(F)
    keys = np.unique(keys)
    return np.stack([keys // width, keys % width], axis=1)


def non_manifold_edge_count(F: np.ndarray) -> int:
    """Number of edges shared by more than two triangles."""
    keys, _ = _edge_keys(F)
    keys.sort()
    # An edge in three or more triangles has its key at i and i + 2.
    thrice = keys[2:] == keys[:-2]
    return int(np.count_nonzero(thrice[1:] & ~thrice[:-1]) + (1 if len(thrice) and thrice[0] else 0))


def adjacency_matrix(F: np.ndarray, n: int) -> sp.csr_matrix:
    """(n, n) symmetric 0/1 vertex adjacency through triangle edges."""
    e = edges(F)
    ones = np.ones(len(e))
    a = sp.coo_matrix((ones, (e[:, 0], e[:, 1])), shape=(n, n))
    return (a + a.T).tocsr()


def connected_component_labels(F: np.ndarray, n: int) -> np.ndarray:
    """(n,) int component label of each vertex; isolated vertices get their own."""
    _, labels = connected_components(adjacency_matrix(F, n), directed=False)
    return labels
