"""Vertices that do not belong to the shape: non-finite ones and far strays.

Every size the add-on measures a mesh by (the voxel grid of the skinning
distances, match distances, tolerances) is the bounding box of its
vertices, so a single vertex dragged 10 km away, or a speck of geometry
left far from the character, blows that box up a thousand times: the voxel
grid then holds the whole character in one cell. This module

- refuses coordinates that are not numbers (:func:`require_finite_positions`;
  Blender stores an infinite coordinate as the largest float32),
- finds *strays*, vertices far outside the box that holds the bulk of the
  vertices (:func:`stray_vertices`), so a job can run on the mesh without
  them (:func:`without_vertices`), and
- gives each group of connected strays the weights of one kept vertex
  (:func:`rows_for_strays`): the one it is joined to by an edge, else the
  nearest, so a stray part follows the body rigidly.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..errors import InputError
from ..messages import listed_names
from .topology import edges

#: Blender stores ``inf`` as the largest float32 (3.4e38); a coordinate of
#: this magnitude or more is treated as infinite.
INFINITE_COORDINATE = float(np.finfo(np.float32).max)
#: Share of the vertices left out at each end of each axis when measuring the
#: box that holds the bulk of a mesh (the *robust box*).
ROBUST_TRIM_FRACTION = 0.01
#: A vertex farther outside the robust box than this many robust sizes (the
#: robust box's diagonal) is a stray. Legitimate parts (a spear, a tail) stay
#: within one size of the bulk; a wrongly placed vertex is usually thousands away.
STRAY_DISTANCE_FACTOR = 1.0


def non_finite_rows(vertices: np.ndarray) -> np.ndarray:
    """(n,) bool: rows with a NaN, an infinite or a float32-maximum coordinate.

    Parameters
    ----------
    vertices : (n, 3) float array

    Examples
    --------
    >>> non_finite_rows(np.array([[0.0, 0, 0], [np.nan, 0, 0], [3.4028235e38, 0, 0]])).tolist()
    [False, True, True]
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    with np.errstate(invalid="ignore"):
        return ~np.all(np.abs(vertices) < INFINITE_COORDINATE, axis=1)


def require_finite_positions(vertices: np.ndarray, object_names: Sequence[str], object_offsets: Sequence[int]) -> None:
    """Raise :class:`InputError` naming the first object with a vertex at an
    infinite or undefined position.

    Parameters
    ----------
    vertices : (n, 3) float array
    object_names : k str, the objects the vertices come from
    object_offsets : (k + 1,) int, vertices ``offsets[i]:offsets[i + 1]`` are object ``i``'s
    """
    bad = non_finite_rows(vertices)
    if not bad.any():
        return
    for index, name in enumerate(object_names):
        local = np.flatnonzero(bad[object_offsets[index]:object_offsets[index + 1]])
        if len(local):
            count = f"{len(local)} vertices" if len(local) > 1 else "a vertex"
            raise InputError(
                f"'{name}' has {count} at an infinite or undefined (NaN) position "
                f"(index {listed_names(local.tolist())}): move or delete {'them' if len(local) > 1 else 'it'} "
                "in Edit Mode first."
            )


def robust_box(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Corners of the box holding the bulk of the vertices: per axis, the
    range left once the ``ROBUST_TRIM_FRACTION`` lowest and highest
    coordinates (at least one each, when there are three or more) are left out.

    Parameters
    ----------
    vertices : (n, 3) float64 array, n >= 1

    Returns
    -------
    low, high : (3,) float64 arrays, ``low <= high``

    Examples
    --------
    >>> low, high = robust_box(np.array([[0.0, 0, 0], [1, 1, 1], [2, 2, 2], [5000, 0, 0]]))
    >>> low.tolist(), high.tolist()
    ([1.0, 0.0, 0.0], [2.0, 1.0, 1.0])
    """
    ordered = np.sort(np.asarray(vertices, dtype=np.float64).reshape(-1, 3), axis=0)
    n = len(ordered)
    trim = min(max(int(np.ceil(ROBUST_TRIM_FRACTION * n)), 1), (n - 1) // 2)
    return ordered[trim], ordered[n - 1 - trim]


def stray_vertices(vertices: np.ndarray) -> np.ndarray:
    """(n,) bool: vertices farther outside the robust box than
    ``STRAY_DISTANCE_FACTOR`` times its diagonal.

    Parameters
    ----------
    vertices : (n, 3) float64 array of finite positions

    Returns
    -------
    (n,) bool array; all False when the bulk has no extent (a flat point
    cloud collapsed to a point) or there are fewer than three vertices.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    if len(vertices) < 3:
        return np.zeros(len(vertices), dtype=bool)
    low, high = robust_box(vertices)
    size = float(np.linalg.norm(high - low))
    if size <= 0.0:
        return np.zeros(len(vertices), dtype=bool)
    outside = np.maximum(low - vertices, 0.0) + np.maximum(vertices - high, 0.0)
    return np.linalg.norm(outside, axis=1) > STRAY_DISTANCE_FACTOR * size


def without_vertices(vertices: np.ndarray, triangles: np.ndarray,
                     drop: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mesh with the ``drop`` vertices and every triangle touching them removed.

    Parameters
    ----------
    vertices : (n, 3) float64 array
    triangles : (m, 3) int array
    drop : (n,) bool array

    Returns
    -------
    kept : (n_kept,) int64 array, original index of each kept vertex
    kept_vertices : (n_kept, 3) float64 array
    kept_triangles : (m_kept, 3) int64 array over the kept vertices
    """
    drop = np.asarray(drop, dtype=bool)
    kept = np.flatnonzero(~drop)
    new_index = np.full(len(drop), -1, dtype=np.int64)
    new_index[kept] = np.arange(len(kept))
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    whole = ~drop[triangles].any(axis=1) if len(triangles) else np.zeros(0, dtype=bool)
    return kept, np.asarray(vertices, dtype=np.float64)[kept], new_index[triangles[whole]]


def rows_for_strays(kept_rows: np.ndarray, vertices: np.ndarray, triangles: np.ndarray, drop: np.ndarray) -> np.ndarray:
    """Rows for every vertex: the kept vertices' ``kept_rows``, and for each
    connected group of dropped vertices the row of one kept vertex, copied
    whole so the group moves rigidly with it: the kept vertex nearest the
    group among those joined to it by an edge, else the nearest of all.

    Parameters
    ----------
    kept_rows : (n_kept, b) float array, rows of the kept vertices (``~drop``), in order
    vertices : (n, 3) float64 array
    triangles : (m, 3) int array over all n vertices
    drop : (n,) bool array, at least one vertex kept

    Returns
    -------
    (n, b) float64 array
    """
    drop = np.asarray(drop, dtype=bool)
    n = len(drop)
    kept_rows = np.asarray(kept_rows, dtype=np.float64)
    rows = np.zeros((n, kept_rows.shape[1]))
    rows[~drop] = kept_rows
    if not drop.any():
        return rows
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    pairs = (edges(np.asarray(triangles, dtype=np.int64).reshape(-1, 3)) if len(triangles)
             else np.zeros((0, 2), np.int64))
    both = drop[pairs].all(axis=1)
    joined = sp.coo_matrix((np.ones(both.sum()), (pairs[both, 0], pairs[both, 1])), shape=(n, n))
    _, group = connected_components(joined, directed=False)
    dropped = np.flatnonzero(drop)
    # Candidate (dropped vertex, kept vertex) pairs: edges leaving a group ...
    crossing = pairs[drop[pairs].sum(axis=1) == 1]
    inner = np.where(drop[crossing[:, 0]], crossing[:, 0], crossing[:, 1])
    outer = np.where(drop[crossing[:, 0]], crossing[:, 1], crossing[:, 0])
    # ... and, for groups with no such edge, the nearest kept vertex in space.
    has_edge = np.zeros(group.max() + 1, dtype=bool)
    has_edge[group[inner]] = True
    loose = dropped[~has_edge[group[dropped]]]
    if len(loose):
        kept_index = np.flatnonzero(~drop)
        _, nearest = cKDTree(vertices[kept_index]).query(vertices[loose])
        inner = np.concatenate([inner, loose])
        outer = np.concatenate([outer, kept_index[nearest]])
    gap = np.linalg.norm(vertices[inner] - vertices[outer], axis=1)
    # Per group, the candidate pair with the smallest gap.
    order = np.lexsort((gap, group[inner]))
    first = np.ones(len(order), dtype=bool)
    first[1:] = group[inner[order[1:]]] != group[inner[order[:-1]]]
    chosen_kept = np.zeros(group.max() + 1, dtype=np.int64)
    chosen_kept[group[inner[order[first]]]] = outer[order[first]]
    rows[dropped] = rows[chosen_kept[group[dropped]]]
    return rows
