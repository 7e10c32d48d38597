"""Welding: joining the copies importers make of one vertex.

glTF, FBX and OBJ importers split a vertex wherever a UV seam or a hard edge
passes through it, so a closed body arrives as patches. Operators that work
along the surface (a Laplacian, smoothing, connected parts, Blender's bone
heat) must see one vertex there, so they run on the welded mesh and map
their results back through ``to_welded``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..types import Mesh, Weights
from ..weights import normalize_rows

#: Vertices closer than this fraction of the mesh's bounding-box diagonal are
#: copies of one vertex split at a seam (2 micrometres on a 2 m character:
#: far above float32 round-off of exported positions, far below any modelled
#: detail).
WELD_FRACTION = 1e-6


def weld_vertices(V: np.ndarray, F: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge vertices closer than ``tolerance`` (chains of such pairs merge too).

    Parameters
    ----------
    V : (n, 3) float64 array
    F : (m, 3) int array
    tolerance : float >= 0, scene units

    Returns
    -------
    welded_V : (n', 3) float64 array, each the mean of its copies
    welded_F : (m', 3) int64 array, triangles that collapsed dropped
    to_welded : (n,) int64 array mapping each original vertex to its welded one
    """
    V = np.asarray(V, dtype=np.float64)
    n = len(V)
    if not n:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), np.zeros(0, dtype=np.int64)
    # Most copies sit at exactly the same place: joining those by sorting
    # first leaves the neighbour search a fraction of the points.
    order = np.lexsort(V.T[::-1])
    ordered = V[order]
    new_place = np.ones(n, dtype=bool)
    new_place[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    to_place = np.empty(n, dtype=np.int64)
    to_place[order] = np.cumsum(new_place) - 1
    places = ordered[new_place]
    pairs = cKDTree(places).query_pairs(r=tolerance, output_type="ndarray")
    m = len(places)
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(m, m))
    _, place_group = connected_components(graph, directed=False)
    groups = place_group[to_place]
    # Numbered by first appearance, as the vertices are ordered.
    _, first = np.unique(groups, return_index=True)
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(first))
    to_welded = rank[groups]
    count = len(first)
    copies = np.maximum(np.bincount(to_welded, minlength=count), 1)
    welded_V = np.stack([np.bincount(to_welded, weights=V[:, k], minlength=count) for k in range(3)], axis=1)
    welded_V /= copies[:, None]
    welded_F = to_welded[F]
    keep = (welded_F[:, 0] != welded_F[:, 1]) & (welded_F[:, 1] != welded_F[:, 2]) & (welded_F[:, 2] != welded_F[:, 0])
    return welded_V, welded_F[keep].astype(np.int64), to_welded.astype(np.int64)


def seam_tolerance(mesh: Mesh) -> float:
    """The weld distance of ``mesh``, scene units: :data:`WELD_FRACTION` of its
    bounding-box diagonal."""
    return WELD_FRACTION * mesh.bounding_box_diagonal


def weld_mesh(mesh: Mesh) -> tuple[Mesh, np.ndarray]:
    """``mesh`` with its seam copies joined (:func:`seam_tolerance`), as one object.

    Returns
    -------
    welded : Mesh named after the first object of ``mesh``
    to_welded : (n,) int64 array, welded vertex of each original vertex
    """
    vertices, triangles, to_welded = weld_vertices(mesh.vertices, mesh.triangles, seam_tolerance(mesh))
    return Mesh(vertices, triangles, object_names=mesh.object_names[:1]), to_welded


def weld_seams(mesh: Mesh, weights: Weights) -> tuple[Mesh, Weights]:
    """Join vertices at the same place (UV seams), averaging their weights.

    Parameters
    ----------
    mesh : Mesh with n vertices
    weights : Weights, (n, b)

    Returns
    -------
    mesh : Mesh, welded (:func:`weld_mesh`), one object
    weights : Weights, (n', b), the sum over each vertex's copies with rows normalised
    """
    welded, to_welded = weld_mesh(mesh)
    summed = np.zeros((welded.vertex_count, weights.matrix.shape[1]))
    np.add.at(summed, to_welded, weights.matrix)
    return welded, Weights(normalize_rows(summed), weights.bone_names)


def weld_objects(mesh: Mesh) -> tuple[list[Mesh], np.ndarray]:
    """Each object of ``mesh`` with its seam copies joined, objects kept apart.

    The tolerance is the whole mesh's (:func:`seam_tolerance`); a triangle
    whose corners lie in two objects belongs to neither and is dropped.

    Returns
    -------
    parts : list of Mesh, one per object, each named after it
    to_welded : (n,) int64 array, row of each original vertex in the
        concatenation of ``parts``
    """
    tolerance = seam_tolerance(mesh)
    parts, maps, offset = [], [], 0
    for index in range(len(mesh.object_names)):
        part = mesh.object_slice(index)
        inside = ((mesh.triangles >= part.start) & (mesh.triangles < part.stop)).all(axis=1)
        vertices, triangles, to_welded = weld_vertices(mesh.vertices[part], mesh.triangles[inside] - part.start,
                                                       tolerance)
        parts.append(Mesh(vertices, triangles, object_names=(mesh.object_names[index],)))
        maps.append(to_welded + offset)
        offset += len(vertices)
    return parts, np.concatenate(maps) if maps else np.zeros(0, dtype=np.int64)
