"""The simplest skinning baseline: every vertex follows its closest bone.

Each vertex gets weight 1 on the deform bone whose segment (head to tail,
Blender's bone) lies closest to it and 0 elsewhere. It ignores the surface,
so vertices of one limb snap to a nearby bone of another limb and joints
crease sharply; it is the floor any real method must beat (issue 4).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..types import Mesh, Skeleton, Weights

#: Point-segment distances are computed for this many vertices at a time,
#: so memory stays at ``POINT_CHUNK * bones`` floats (a few MB) on any mesh.
POINT_CHUNK = 4096


def closest_segments(points: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index of and distance to the closest segment of every point.

    Parameters
    ----------
    points : (n, 3) float64 array
    starts, ends : (s, 3) float64 array
        Segment end points; a zero-length segment is a point.

    Returns
    -------
    index : (n,) int64 array
        Closest segment per point; the lowest index wins ties.
    distance : (n,) float64 array
        Euclidean distance to it.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    starts = np.asarray(starts, dtype=np.float64).reshape(-1, 3)
    ends = np.asarray(ends, dtype=np.float64).reshape(-1, 3)
    if not len(starts):
        raise InputError("There are no bones to measure distances to.")
    direction = ends - starts
    squared_length = np.einsum("sk,sk->s", direction, direction)
    safe_length = np.where(squared_length > 0.0, squared_length, 1.0)
    index = np.empty(len(points), dtype=np.int64)
    distance = np.empty(len(points))
    for first in range(0, len(points), POINT_CHUNK):
        chunk = points[first:first + POINT_CHUNK]
        offset = chunk[:, None, :] - starts[None, :, :]
        t = np.clip(np.einsum("psk,sk->ps", offset, direction) / safe_length, 0.0, 1.0)
        t[:, squared_length <= 0.0] = 0.0
        gap = offset - t[:, :, None] * direction[None, :, :]
        squared = np.einsum("psk,psk->ps", gap, gap)
        nearest = np.argmin(squared, axis=1)
        index[first:first + len(chunk)] = nearest
        distance[first:first + len(chunk)] = np.sqrt(squared[np.arange(len(chunk)), nearest])
    return index, distance


def nearest_bone_weights(mesh: Mesh, skeleton: Skeleton) -> Weights:
    """Weights giving each vertex wholly to its closest deform bone.

    Parameters
    ----------
    mesh : Mesh
        ``n`` vertices, in the skeleton's space.
    skeleton : Skeleton
        Only deform bones (:meth:`Skeleton.deform_subset`) receive weight;
        each is the segment from its head (``joints``) to its ``tails``.

    Returns
    -------
    Weights
        ``(n, d)`` one-hot rows, columns the ``d`` deform bones in
        ``deform_subset`` order.

    Raises
    ------
    InputError
        When the skeleton has no deform bone.
    """
    deform = skeleton.deform_subset()
    if deform.bone_count == 0:
        raise InputError("The skeleton has no deform bones: turn on Deform for the bones that should move the mesh.")
    index, _ = closest_segments(mesh.vertices, deform.joints, deform.tails)
    matrix = np.zeros((mesh.vertex_count, deform.bone_count))
    matrix[np.arange(mesh.vertex_count), index] = 1.0
    return Weights(matrix, deform.names)
