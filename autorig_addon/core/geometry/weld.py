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
        vertices, triangles, to_welded = weld_vertices(mesh.vertices[part], mesh.triangles[inside] - part.start, tolerance)
        parts.append(Mesh(vertices, triangles, object_names=(mesh.object_names[index],)))
        maps.append(to_welded + offset)
        offset += len(vertices)
    return parts, np.concatenate(maps) if maps else np.zeros(0, dtype=np.int64)
