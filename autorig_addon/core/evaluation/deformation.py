"""Deformation error: how far a mesh posed with predicted weights lies from
the same mesh posed with reference weights.

Both weight sets skin the mesh (:mod:`..skeleton.posing`, Blender's Armature
modifier semantics) in the same poses, and each vertex's distance between
the two results is measured in units of the character's size. Used by the
evaluation of skin weights and of weight transfer.
"""

from __future__ import annotations

import numpy as np

from ..geometry.bounding_box import character_size, checked_size
from ..skeleton.posing import posed_vertices, random_poses
from ..types import Skeleton
from .deform_weights import deform_weight_matrix


def deformation_error(
    vertices: np.ndarray,
    weights_pred,
    weights_ref,
    skeleton: Skeleton,
    poses: np.ndarray | None = None,
    size: float | None = None,
) -> dict:
    """How far the mesh posed with predicted weights lies from the reference.

    For every pose both weight sets skin the mesh
    (:func:`~..skeleton.posing.linear_blend_skinning`: a vertex moves by the
    weighted mean of its bones' matrices, one without weight stays at rest)
    and each vertex's distance between the two results is taken. The
    distances of all vertices in all poses are pooled.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions.
    weights_pred, weights_ref : (n, d) float64 array or Weights
        See :func:`~.deform_weights.deform_weight_matrix`.
    skeleton : Skeleton
        Rest skeleton; its ``d`` deform bones are posed.
    poses : (p, d, 3, 3) float64 array, optional
        Local rotations; default :func:`~..skeleton.posing.random_poses` with
        its defaults (10 seeded poses, 30 % of the bones, angles from
        N(0, 25 degrees)).
    size : float, optional
        Length the distances are divided by; default the character's size,
        the bounding-box diagonal of ``vertices``
        (:func:`~..geometry.bounding_box.character_size`).

    Returns
    -------
    dict with float values
        ``mean`` and ``max`` of the distances divided by ``size``
        (0 for no poses or no vertices).
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    pred = deform_weight_matrix(weights_pred, skeleton, len(vertices), "predicted weights")
    ref = deform_weight_matrix(weights_ref, skeleton, len(vertices), "reference weights")
    size = character_size(vertices) if size is None else checked_size(size)
    if poses is None:
        poses = random_poses(skeleton)
    # Skinning divides by each vertex's total weight, so it is not linear in
    # the weights: both meshes are posed, then compared.
    distance = np.linalg.norm(
        posed_vertices(vertices, pred, skeleton, poses) - posed_vertices(vertices, ref, skeleton, poses), axis=-1
    )
    if not distance.size:
        return {"mean": 0.0, "max": 0.0}
    return {"mean": float(distance.mean()) / size, "max": float(distance.max()) / size}
