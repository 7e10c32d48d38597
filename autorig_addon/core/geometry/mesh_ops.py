"""Differential operators and topology helpers on triangle meshes.

Conventions (as in gpytoolbox): ``V`` is an (n, 3) float64 array of
positions, ``F`` an (m, 3) int array of triangles. Sparse results are
``scipy.sparse.csr_matrix``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

#: Relative guard on triangle doubled areas: below ``AREA_GUARD * edge_length^2``
#: a triangle counts as degenerate, so cotangents stay finite.
AREA_GUARD = 1e-12


def triangle_double_areas(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m,) float64: twice the area of each triangle."""
    return np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


def triangle_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m, 3) float64 unit normals (zero for degenerate triangles)."""
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def vertex_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(n, 3) float64 area-weighted unit vertex normals (zero where no face)."""
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    normals = np.zeros((len(V), 3))
    for corner in range(3):
        np.add.at(normals, F[:, corner], n)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)


def _corner_cotangents(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(m, 3): cotangent of the angle at corner k of each triangle, finite
    even for degenerate triangles."""
    cot = np.empty((len(F), 3))
    for k in range(3):
        a = V[F[:, (k + 1) % 3]] - V[F[:, k]]
        b = V[F[:, (k + 2) % 3]] - V[F[:, k]]
        dot = np.einsum("ij,ij->i", a, b)
        cross = np.linalg.norm(np.cross(a, b), axis=1)
        guard = AREA_GUARD * (np.einsum("ij,ij->i", a, a) + np.einsum("ij,ij->i", b, b))
        cot[:, k] = dot / np.maximum(cross, np.maximum(guard, 1e-300))
    return cot


def cotangent_laplacian(V: np.ndarray, F: np.ndarray) -> sp.csr_matrix:
    """Cotangent Laplacian ``L`` (n, n), negative semi-definite.

    ``L[i, j] = (cot a_ij + cot b_ij) / 2`` for each edge, diagonal minus the
    row sum, so rows sum to zero and ``-L`` is the Dirichlet energy matrix.
    Degenerate triangles contribute finite (possibly large) entries, never NaN.
    """
    n = len(V)
    cot = _corner_cotangents(V, F)
    # The angle at corner k is opposite the edge between corners k+1 and k+2.
    rows = np.concatenate([F[:, (k + 1) % 3] for k in range(3)])
    cols = np.concatenate([F[:, (k + 2) % 3] for k in range(3)])
    values = 0.5 * np.concatenate([cot[:, k] for k in range(3)])
    off = sp.coo_matrix((values, (rows, cols)), shape=(n, n))
    off = (off + off.T).tocsr()
    return (off - sp.diags(np.asarray(off.sum(axis=1)).ravel())).tocsr()


def voronoi_mass(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """(n,) float64 lumped mass: each vertex's mixed Voronoi area (Meyer et al. 2003).

    Obtuse triangles give half their area to the obtuse corner and a quarter
    to the others. Vertices in no triangle get zero.
    """
    area = 0.5 * triangle_double_areas(V, F)
    cot = _corner_cotangents(V, F)
    corner_area = np.zeros((len(F), 3))
    for k in range(3):
        e_next = np.sum((V[F[:, (k + 2) % 3]] - V[F[:, k]]) ** 2, axis=1)  # edge k -> k+2
        e_prev = np.sum((V[F[:, (k + 1) % 3]] - V[F[:, k]]) ** 2, axis=1)  # edge k -> k+1
        # Voronoi part: 1/8 (|e_prev|^2 cot(angle at k+2) + |e_next|^2 cot(angle at k+1))
        corner_area[:, k] = 0.125 * (e_prev * cot[:, (k + 2) % 3] + e_next * cot[:, (k + 1) % 3])
    obtuse = cot < 0
    any_obtuse = obtuse.any(axis=1)
    corner_area[any_obtuse] = np.where(obtuse[any_obtuse], 0.5, 0.25) * area[any_obtuse, None]
    # Degenerate triangles: split their (tiny) area evenly, never negative.
    bad = ~np.isfinite(corner_area).all(axis=1) | (corner_area < 0).any(axis=1)
    corner_area[bad] = area[bad, None] / 3.0
    mass = np.zeros(len(V))
    for k in range(3):
        np.add.at(mass, F[:, k], corner_area[:, k])
    return mass


def edges(F: np.ndarray) -> np.ndarray:
    """(e, 2) int64 unique undirected edges, smaller index first."""
    all_edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    all_edges.sort(axis=1)
    return np.unique(all_edges, axis=0)


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


def weld_vertices(V: np.ndarray, F: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge vertices closer than ``tolerance`` (UV and normal seams split them).

    Returns
    -------
    welded_V : (n', 3) float64 array
    welded_F : (m', 3) int64 array, triangles that collapsed dropped
    to_welded : (n,) int64 array mapping each original vertex to its welded one
    """
    pairs = cKDTree(V).query_pairs(r=tolerance, output_type="ndarray") if len(V) else np.zeros((0, 2), int)
    n = len(V)
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, to_welded = connected_components(graph, directed=False)
    count = to_welded.max() + 1 if n else 0
    welded_V = np.zeros((count, 3))
    np.add.at(welded_V, to_welded, V)
    welded_V /= np.maximum(np.bincount(to_welded, minlength=count), 1)[:, None]
    welded_F = to_welded[F]
    keep = (welded_F[:, 0] != welded_F[:, 1]) & (welded_F[:, 1] != welded_F[:, 2]) & (welded_F[:, 2] != welded_F[:, 0])
    return welded_V, welded_F[keep].astype(np.int64), to_welded.astype(np.int64)


def non_manifold_edge_count(F: np.ndarray) -> int:
    """Number of edges shared by more than two triangles."""
    all_edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    all_edges.sort(axis=1)
    _, counts = np.unique(all_edges, axis=0, return_counts=True)
    return int(np.count_nonzero(counts > 2))


def smooth_over_edges(values: np.ndarray, F: np.ndarray, iterations: int, strength: float,
                      rows: np.ndarray | None = None) -> np.ndarray:
    """Uniform Laplacian smoothing of per-vertex ``values`` along mesh edges.

    Each pass replaces a row by ``(1 - strength) * row + strength * mean of
    its edge neighbours' rows``. Only ``rows`` (bool mask, default all)
    change; vertices without edges keep their rows, so loose parts never
    exchange values.

    Parameters
    ----------
    values : (n, k) float64 array
    F : (m, 3) int array
    iterations : int >= 0
    strength : float in [0, 1]
    rows : (n,) bool array or None

    Returns
    -------
    (n, k) float64 array (a new one; ``values`` is not modified).
    """
    smoothed = np.array(values, dtype=np.float64, copy=True)
    if iterations <= 0 or strength <= 0 or not len(F):
        return smoothed
    adjacency = adjacency_matrix(F, len(smoothed))
    degree = np.asarray(adjacency.sum(axis=1)).ravel()
    moving = degree > 0 if rows is None else np.asarray(rows, dtype=bool) & (degree > 0)
    if not moving.any():
        return smoothed
    for _ in range(int(iterations)):
        mean = (adjacency @ smoothed)[moving] / degree[moving, None]
        smoothed[moving] = (1.0 - strength) * smoothed[moving] + strength * mean
    return smoothed
