"""Posing a skeleton and the mesh skinned to it (linear blend skinning).

Every function here works on the *deform bones* of a skeleton, in the order
of :meth:`Skeleton.deform_subset`: bone ``k`` below means the ``k``-th deform
bone, which is also column ``k`` of every weight matrix. Non-deform bones
(controls, mechanism bones) never move a vertex, so they are left out.

A pose is given as one *local rotation* per deform bone, ``(d, 3, 3)``: bone
``k`` turns by ``local_rotations[k]`` about its own head, with the axes of the
armature's rest space, and carries its descendants along. The identity
everywhere is the rest pose.

Skinning follows Blender's Armature modifier (vertex groups, no envelopes,
no preserve volume): a vertex moves by the weighted mean of its bones'
matrices, i.e. the weighted sum divided by the vertex's total weight, so
weights need not sum to one; a vertex whose weights total
:data:`MIN_DEFORMING_TOTAL_WEIGHT` or less stays where it is.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..types import Skeleton

#: Number of random poses of the deformation error (RigNet's protocol).
DEFAULT_POSE_COUNT = 10

#: Share of the deform bones rotated in each random pose (0.3 = 30 %).
DEFAULT_POSED_FRACTION = 0.3

#: Standard deviation of the random rotation angles, in degrees.
DEFAULT_ANGLE_SIGMA_DEGREES = 25.0

#: A vertex whose weights total this or less is not deformed (weight units).
#: Blender's Armature modifier uses the same bound (``contrib > 0.0001`` in
#: ``armature_deform.cc``) so that it never divides by a vanishing total.
MIN_DEFORMING_TOTAL_WEIGHT = 1e-4


def random_poses(
    skeleton: Skeleton,
    count: int = DEFAULT_POSE_COUNT,
    seed: int = 0,
    fraction: float = DEFAULT_POSED_FRACTION,
    sigma_degrees: float = DEFAULT_ANGLE_SIGMA_DEGREES,
) -> np.ndarray:
    """Seeded random poses: in each, a random share of the bones turns.

    In every pose ``max(1, round(fraction * d))`` distinct deform bones are
    drawn uniformly; each turns about an axis drawn uniformly on the unit
    sphere by an angle drawn from ``N(0, sigma_degrees)``. The other bones
    keep the identity. The same arguments always give the same poses.

    Parameters
    ----------
    skeleton : Skeleton
        Only its deform bones are posed (``d`` of them).
    count : int
        Number of poses.
    seed : int
        Seed of the ``numpy.random.default_rng`` generator.
    fraction : float in [0, 1]
        Share of the deform bones rotated per pose.
    sigma_degrees : float
        Standard deviation of the rotation angle, in degrees.

    Returns
    -------
    local_rotations : (count, d, 3, 3) float64 array
        Rotation matrices, see the module docstring.
    """
    if count < 0:
        raise InputError(f"The number of poses must not be negative, got {count}.")
    if not 0.0 <= fraction <= 1.0:
        raise InputError(f"The share of posed bones must lie in [0, 1], got {fraction}.")
    bone_count = skeleton.deform_subset().bone_count
    rotations = np.broadcast_to(np.eye(3), (count, bone_count, 3, 3)).copy()
    if bone_count == 0 or count == 0 or fraction == 0.0:
        return rotations
    posed_per_pose = max(1, int(round(fraction * bone_count)))
    rng = np.random.default_rng(seed)
    # argsort of uniform noise = an independent random permutation per pose.
    chosen = np.argsort(rng.random((count, bone_count)), axis=1)[:, :posed_per_pose]
    axes = rng.normal(size=(count, posed_per_pose, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    angles = np.radians(rng.normal(0.0, sigma_degrees, size=(count, posed_per_pose)))
    pose_index = np.repeat(np.arange(count), posed_per_pose)
    rotations[pose_index, chosen.ravel()] = axis_angle_matrices(axes.reshape(-1, 3), angles.ravel())
    return rotations


def axis_angle_matrices(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rotation matrices from axes and angles (Rodrigues' formula).

    Parameters
    ----------
    axes : (k, 3) float64 array
        Unit rotation axes.
    angles : (k,) float64 array
        Angles in radians, counter-clockwise looking down the axis.

    Returns
    -------
    rotations : (k, 3, 3) float64 array
    """
    axes = np.asarray(axes, dtype=np.float64).reshape(-1, 3)
    angles = np.asarray(angles, dtype=np.float64).reshape(-1)
    cross = np.zeros((len(axes), 3, 3))
    cross[:, 0, 1], cross[:, 0, 2] = -axes[:, 2], axes[:, 1]
    cross[:, 1, 0], cross[:, 1, 2] = axes[:, 2], -axes[:, 0]
    cross[:, 2, 0], cross[:, 2, 1] = -axes[:, 1], axes[:, 0]
    sine = np.sin(angles)[:, None, None]
    versine = (1.0 - np.cos(angles))[:, None, None]
    return np.eye(3) + sine * cross + versine * (cross @ cross)


def pose_matrices(skeleton: Skeleton, local_rotations: np.ndarray) -> np.ndarray:
    """World skinning matrices of a pose, composed down the hierarchy.

    Deform bone ``k`` with head ``h`` and parent ``p`` gets
    ``M[k] = M[p] @ T(h) @ R[k] @ T(-h)``: it turns about its rest head and
    then follows its parent. Roots use ``M[p] = I``. Identity rotations give
    identity matrices (the rest pose).

    Parameters
    ----------
    skeleton : Skeleton
        Its deform bones (``d``) are posed.
    local_rotations : (..., d, 3, 3) float64 array
        One rotation per deform bone; leading axes (several poses) are kept.

    Returns
    -------
    matrices : (..., d, 4, 4) float64 array
        Maps rest-space positions to posed positions, per bone.
    """
    deform = skeleton.deform_subset()
    rotations = np.asarray(local_rotations, dtype=np.float64)
    if rotations.shape[-3:] != (deform.bone_count, 3, 3):
        raise InputError(
            f"Expected one 3x3 rotation per deform bone ({deform.bone_count}), got an array of shape {rotations.shape}."
        )
    heads = deform.joints
    local = np.zeros(rotations.shape[:-2] + (4, 4))
    local[..., :3, :3] = rotations
    # T(h) R T(-h) moves x to R (x - h) + h, so its translation is h - R h.
    local[..., :3, 3] = heads - np.einsum("...ij,...j->...i", rotations, heads)
    local[..., 3, 3] = 1.0
    world = local.copy()
    # Parents come first, so one pass down the joint order composes the chain.
    for bone, parent in enumerate(deform.parents):
        if parent >= 0:
            world[..., bone, :, :] = world[..., parent, :, :] @ local[..., bone, :, :]
    return world


def linear_blend_skinning(vertices: np.ndarray, weights: np.ndarray, matrices: np.ndarray) -> np.ndarray:
    """Posed positions as Blender's Armature modifier computes them.

    Vertex ``v`` with weights ``w`` totalling ``W = sum_k w[k]`` goes to
    ``sum_k w[k] M[k] v / W``: the weighted sum of its bones' matrices is
    divided by the total, so ``(0.25, 0.25)`` moves a vertex exactly like
    ``(0.5, 0.5)``. A vertex with ``W <=`` :data:`MIN_DEFORMING_TOTAL_WEIGHT`
    (no weight at all, say) stays at its rest position.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions.
    weights : (n, b) float64 array
        Non-negative, as Blender's vertex groups; column ``k`` belongs to
        ``matrices[k]``.
    matrices : (b, 4, 4) float64 array
        Skinning matrices, e.g. from :func:`pose_matrices`.

    Returns
    -------
    posed : (n, 3) float64 array
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    weights = np.asarray(weights, dtype=np.float64)
    matrices = np.asarray(matrices, dtype=np.float64)
    if weights.shape != (len(vertices), len(matrices)):
        raise InputError(
            f"Weights of shape {weights.shape} do not fit {len(vertices)} vertices and {len(matrices)} bones."
        )
    total = weights.sum(axis=1)
    moving = total > MIN_DEFORMING_TOTAL_WEIGHT
    blended = (weights[moving] @ matrices[:, :3, :].reshape(len(matrices), 12)).reshape(-1, 3, 4)
    posed = vertices.copy()
    moved = np.einsum("nij,nj->ni", blended[:, :, :3], vertices[moving]) + blended[:, :, 3]
    posed[moving] = moved / total[moving, None]
    return posed


def posed_vertices(vertices: np.ndarray, weights: np.ndarray, skeleton: Skeleton,
                   local_rotations: np.ndarray) -> np.ndarray:
    """The mesh skinned to ``skeleton`` in each of several poses.

    :func:`pose_matrices` of every pose, then :func:`linear_blend_skinning`.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions.
    weights : (n, d) float64 array
        Columns are the deform bones of ``skeleton``.
    skeleton : Skeleton
    local_rotations : (p, d, 3, 3) float64 array
        ``p`` poses, e.g. from :func:`random_poses`.

    Returns
    -------
    posed : (p, n, 3) float64 array
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    bone_count = skeleton.deform_subset().bone_count
    matrices = pose_matrices(skeleton, local_rotations).reshape((-1, bone_count, 4, 4))
    posed = np.empty((len(matrices),) + vertices.shape)
    for index, pose_matrix in enumerate(matrices):
        posed[index] = linear_blend_skinning(vertices, weights, pose_matrix)
    return posed
