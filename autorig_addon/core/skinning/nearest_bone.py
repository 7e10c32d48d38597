"""The simplest skinning baseline: every vertex follows its closest bone.

Each vertex gets weight 1 on the deform bone whose segment (head to tail,
Blender's bone) lies closest to it and 0 elsewhere. It ignores the surface,
so vertices of one limb snap to a nearby bone of another limb and joints
crease sharply; it is the floor any real method must beat (issue 4).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..geometry.segments import closest_segments
from ..types import Mesh, Skeleton, Weights


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
