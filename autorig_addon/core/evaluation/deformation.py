"""Posing a skinned mesh and measuring how it deforms.

Used by the evaluation of skin weights and weight transfer: two weight
matrices for the same mesh and skeleton are compared by posing the mesh with
each (linear blend skinning) and measuring how far the results lie apart; a
transfer without a reference is judged by how much its edges stretch.

Every function here works on the *deform bones* of a skeleton, in the order
of :meth:`Skeleton.deform_subset`: bone ``k`` below means the ``k``-th deform
bone, which is also column ``k`` of every weight matrix. Non-deform bones
(controls, mechanism bones) never move a vertex, so they are left out.

A pose is given as one *local rotation* per deform bone, ``(d, 3, 3)``: bone
``k`` turns by ``local_rotations[k]`` about its own head, with the axes of the
armature's rest space, and carries its descendants along. The identity
everywhere is the rest pose.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..types import Skeleton, Weights

#: Number of random poses of the deformation error (RigNet's protocol).
DEFAULT_POSE_COUNT = 10

#: Share of the deform bones rotated in each random pose (0.3 = 30 %).
DEFAULT_POSED_FRACTION = 0.3

#: Standard deviation of the random rotation angles, in degrees.
DEFAULT_ANGLE_SIGMA_DEGREES = 25.0

#: Rest edges shorter than this share of the mesh size are skipped by
#: :func:`edge_stretch`: their relative change is numerically meaningless.
DEGENERATE_EDGE_FRACTION = 1e-9


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
    """Posed positions: each vertex moves by the weighted sum of its bones' matrices.

    Weights are used as given; rows should sum to one (a row summing to less
    pulls its vertex towards the origin).

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions.
    weights : (n, b) float64 array
        Column ``k`` belongs to ``matrices[k]``.
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
    blended = (weights @ matrices[:, :3, :].reshape(len(matrices), 12)).reshape(-1, 3, 4)
    return np.einsum("nij,nj->ni", blended[:, :, :3], vertices) + blended[:, :, 3]


def deform_weight_matrix(weights, skeleton: Skeleton, vertex_count: int, what: str = "weights") -> np.ndarray:
    """Dense ``(n, d)`` weights whose columns are the deform bones of ``skeleton``.

    Parameters
    ----------
    weights : (n, d) float64 array or Weights
        An array is taken to be in deform-bone order already; a
        :class:`Weights` is matched to the deform bones by name (a bone it
        lacks gets zeros, bones the skeleton lacks are dropped).
    skeleton : Skeleton
    vertex_count : int
        Expected number of rows ``n``.
    what : str
        Names the weights in error messages.

    Returns
    -------
    matrix : (n, d) float64 array
    """
    deform = skeleton.deform_subset()
    if isinstance(weights, Weights):
        matrix = weights.select_bones(deform.names).matrix
    else:
        matrix = np.asarray(weights, dtype=np.float64)
    if matrix.shape != (vertex_count, deform.bone_count):
        raise InputError(
            f"The {what} have shape {matrix.shape} but the mesh has {vertex_count} vertices "
            f"and the skeleton {deform.bone_count} deform bones."
        )
    if not np.all(np.isfinite(matrix)):
        raise InputError(f"The {what} contain NaN or infinite values; clean them first.")
    return matrix


def character_size(vertices: np.ndarray) -> float:
    """Size of a character: the diagonal of its rest mesh's bounding box.

    Parameters
    ----------
    vertices : (n, 3) float64 array

    Returns
    -------
    size : float, in the units of ``vertices``
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    if not len(vertices):
        raise InputError("The mesh has no vertices, so it has no size to measure errors against.")
    size = float(np.linalg.norm(vertices.max(0) - vertices.min(0)))
    if size <= 0.0:
        raise InputError("All vertices lie at one point, so the mesh has no size to measure errors against.")
    return size


def deformation_error(
    vertices: np.ndarray,
    weights_pred,
    weights_ref,
    skeleton: Skeleton,
    poses: np.ndarray | None = None,
    size: float | None = None,
) -> dict:
    """How far the mesh posed with predicted weights lies from the reference.

    For every pose both weight sets skin the mesh (:func:`linear_blend_skinning`)
    and each vertex's distance between the two results is taken. The
    distances of all vertices in all poses are pooled.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions.
    weights_pred, weights_ref : (n, d) float64 array or Weights
        See :func:`deform_weight_matrix`.
    skeleton : Skeleton
        Rest skeleton; its ``d`` deform bones are posed.
    poses : (p, d, 3, 3) float64 array, optional
        Local rotations; default :func:`random_poses` with its defaults
        (10 seeded poses, 30 % of the bones, angles from N(0, 25 degrees)).
    size : float, optional
        Length the distances are divided by; default the character's size,
        the bounding-box diagonal of the rest mesh (:func:`character_size`).

    Returns
    -------
    dict with float values
        ``mean`` and ``max`` of the distances divided by ``size``
        (0 for no poses).
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    pred = deform_weight_matrix(weights_pred, skeleton, len(vertices), "predicted weights")
    ref = deform_weight_matrix(weights_ref, skeleton, len(vertices), "reference weights")
    size = character_size(vertices) if size is None else _positive_size(size)
    if poses is None:
        poses = random_poses(skeleton)
    bone_count = skeleton.deform_subset().bone_count
    matrices = pose_matrices(skeleton, poses).reshape((-1, bone_count, 4, 4))
    # Skinning is linear in the weights, so skinning with the weight
    # difference gives the difference of the two posed meshes directly.
    difference = pred - ref
    total, largest = 0.0, 0.0
    for pose_matrix in matrices:
        distance = np.linalg.norm(linear_blend_skinning(vertices, difference, pose_matrix), axis=1)
        total += float(distance.sum())
        largest = max(largest, float(distance.max(initial=0.0)))
    samples = len(vertices) * len(matrices)
    return {
        "mean": total / samples / size if samples else 0.0,
        "max": largest / size,
    }


def unique_edges(triangles: np.ndarray) -> np.ndarray:
    """Each undirected edge of a triangle mesh once.

    Parameters
    ----------
    triangles : (m, 3) int64 array

    Returns
    -------
    edges : (e, 2) int64 array
        Sorted pairs (smaller index first), sorted lexicographically.
    """
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    edges = np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    return np.unique(np.sort(edges, axis=1), axis=0)


def edge_stretch(vertices: np.ndarray, edges: np.ndarray, posed_vertices: np.ndarray) -> dict:
    """Relative change of edge lengths between rest and posed meshes.

    The stretch of an edge is ``|l_posed - l_rest| / l_rest``; shrinking
    counts like stretching. Edges whose rest length is below
    :data:`DEGENERATE_EDGE_FRACTION` of the rest bounding-box diagonal are
    skipped. Stretches of all edges in all poses are pooled.

    Parameters
    ----------
    vertices : (n, 3) float64 array
        Rest positions.
    edges : (e, 2) int64 array
        Vertex index pairs, e.g. from :func:`unique_edges`.
    posed_vertices : (n, 3) or (p, n, 3) float64 array
        One or several posed copies of ``vertices``.

    Returns
    -------
    dict with float values
        ``p99``: 99th percentile (linear interpolation) and ``max`` of the
        relative stretch (a ratio, 0.1 = 10 %). Both 0 when no edge counts.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    posed = np.asarray(posed_vertices, dtype=np.float64)
    posed = posed.reshape((-1,) + vertices.shape) if posed.size else posed.reshape(0, *vertices.shape)
    if len(edges) and (edges.min() < 0 or edges.max() >= len(vertices)):
        raise InputError("An edge refers to a vertex that does not exist.")
    rest_length = np.linalg.norm(vertices[edges[:, 1]] - vertices[edges[:, 0]], axis=1)
    scale = float(np.linalg.norm(vertices.max(0) - vertices.min(0))) if len(vertices) else 0.0
    valid = rest_length > DEGENERATE_EDGE_FRACTION * scale
    edges, rest_length = edges[valid], rest_length[valid]
    if not len(edges) or not len(posed):
        return {"p99": 0.0, "max": 0.0}
    posed_length = np.linalg.norm(posed[:, edges[:, 1]] - posed[:, edges[:, 0]], axis=2)
    stretch = np.abs(posed_length - rest_length) / rest_length
    return {"p99": float(np.percentile(stretch, 99.0)), "max": float(stretch.max())}


def posed_edge_stretch(
    vertices: np.ndarray,
    edges: np.ndarray,
    weights,
    skeleton: Skeleton,
    poses: np.ndarray | None = None,
) -> dict:
    """Edge stretch of a mesh skinned with ``weights`` over several poses.

    Parameters
    ----------
    vertices : (n, 3) float64 array
    edges : (e, 2) int64 array
    weights : (n, d) float64 array or Weights
        See :func:`deform_weight_matrix`.
    skeleton : Skeleton
    poses : (p, d, 3, 3) float64 array, optional
        Default :func:`random_poses` with its defaults.

    Returns
    -------
    dict with float values
        ``p99`` and ``max`` as in :func:`edge_stretch`.
    """
    vertices = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    matrix = deform_weight_matrix(weights, skeleton, len(vertices))
    if poses is None:
        poses = random_poses(skeleton)
    matrices = pose_matrices(skeleton, poses).reshape((-1, skeleton.deform_subset().bone_count, 4, 4))
    posed = np.zeros((len(matrices),) + vertices.shape)
    for index, pose_matrix in enumerate(matrices):
        posed[index] = linear_blend_skinning(vertices, matrix, pose_matrix)
    return edge_stretch(vertices, edges, posed)


def _positive_size(size: float) -> float:
    size = float(size)
    if not np.isfinite(size) or size <= 0.0:
        raise InputError(f"The character size must be a positive length, got {size}.")
    return size
