"""Metrics comparing a predicted skeleton with a reference skeleton.

Follows the skeleton evaluation of RigNet (Xu et al. 2020). This module
holds the symmetric Chamfer distances CD-J2J, CD-J2B and CD-B2B between
joints, joints and bones, and bones and bones; each is the mean of the two
one-way averages ``(mean_a d(a, B) + mean_b d(b, A)) / 2``.
:func:`evaluate_rig` adds the joint IoU, precision and recall of
:mod:`.joint_matching` and the hierarchy distance of
:mod:`.tree_edit_distance`.

A *bone* here is the segment from a joint's parent to the joint (RigNet's
definition); Blender's tails of leaf bones are not used, because predicted
and artist tails of leaves are arbitrary. A joint without parent or children
counts as a zero-length bone so that it is not ignored.

:func:`evaluate_rig` first keeps only deform bones
(:meth:`Skeleton.deform_subset`) and merges joints at the same place
(:func:`merge_coincident_joints`); it reports distances in units of the
character's size, which ``eval rig`` takes as RigNet does: the largest side
of the rest mesh's bounding box (:func:`~..geometry.bounding_box.largest_side`).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..errors import InputError
from ..geometry.bounding_box import checked_size
from ..geometry.segments import point_segment_distances
from ..types import Skeleton
from .joint_matching import JOINT_MATCH_FRACTION, checked_joints, joint_iou_precision_recall
from .tree_edit_distance import tree_edit_distance

#: Joints closer than this share of the character size are one joint.
COINCIDENT_JOINT_FRACTION = 1e-3

#: Spacing of the points sampled along bones for CD-B2B, as a share of the
#: character size. RigNet steps 0.005 along bones of characters scaled to
#: unit size.
BONE_SAMPLE_FRACTION = 0.005


def merge_coincident_joints(skeleton: Skeleton, tolerance: float) -> Skeleton:
    """The skeleton with joints at the same place merged into one.

    Joints are grouped by single linkage: two joints closer than or at
    ``tolerance`` are in the same group, and so are chains of such pairs.
    Each group becomes one joint at the position, name, tail and deform flag
    of its first member (lowest index). Its parent is the group of that
    member's parent; children of any member become children of the group.
    Order stays parents first.

    Parameters
    ----------
    skeleton : Skeleton
    tolerance : float
        Distance in the skeleton's units.

    Returns
    -------
    merged : Skeleton
        With ``g <= j`` joints; ``skeleton`` itself when nothing merges.
    """
    joints = skeleton.joints
    pairs = (cKDTree(joints).query_pairs(float(tolerance), output_type="ndarray") if len(joints)
             else np.zeros((0, 2), int))
    if not len(pairs):
        return skeleton
    count = len(joints)
    adjacency = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(count, count))
    _, component = connected_components(adjacency, directed=False)
    # First (lowest-index) member of each group; groups are renumbered by it
    # so that a parent group (whose first member has a lower index) comes first.
    first_member = np.full(component.max() + 1, count, dtype=np.int64)
    np.minimum.at(first_member, component, np.arange(count))
    order = np.argsort(first_member)
    group_index = np.empty_like(order)
    group_index[order] = np.arange(len(order))
    representatives = first_member[order]
    parent_joint = skeleton.parents[representatives]
    parents = np.where(parent_joint >= 0, group_index[component[np.maximum(parent_joint, 0)]], -1)
    return Skeleton(
        joints[representatives],
        parents,
        tuple(skeleton.names[j] for j in representatives),
        skeleton.tails[representatives],
        skeleton.deform[representatives],
    )


def bone_segments(skeleton: Skeleton) -> np.ndarray:
    """The bones of a skeleton as segments from parent joint to child joint.

    A joint with neither parent nor children adds a zero-length segment at
    itself.

    Parameters
    ----------
    skeleton : Skeleton

    Returns
    -------
    segments : (s, 2, 3) float64 array
        ``segments[i, 0]`` is the parent end, ``segments[i, 1]`` the child end.
    """
    joints, parents = skeleton.joints, skeleton.parents
    has_parent = parents >= 0
    has_child = np.zeros(len(joints), dtype=bool)
    has_child[parents[has_parent]] = True
    isolated = ~has_parent & ~has_child
    starts = np.concatenate([joints[parents[has_parent]], joints[isolated]])
    ends = np.concatenate([joints[has_parent], joints[isolated]])
    return np.stack([starts, ends], axis=1)


def sample_bones(segments: np.ndarray, spacing: float) -> np.ndarray:
    """Points along bone segments, evenly spaced and including both ends.

    A segment of length ``L`` gets ``max(1, ceil(L / spacing)) + 1`` points,
    so neighbours are at most ``spacing`` apart.

    Parameters
    ----------
    segments : (s, 2, 3) float64 array
    spacing : float
        Largest distance between neighbouring samples, > 0.

    Returns
    -------
    points : (k, 3) float64 array
    """
    segments = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 3)
    if spacing <= 0:
        raise InputError(f"The bone sample spacing must be positive, got {spacing}.")
    lengths = np.linalg.norm(segments[:, 1] - segments[:, 0], axis=1)
    intervals = np.maximum(1, np.ceil(lengths / spacing)).astype(np.int64)
    segment_of_point = np.repeat(np.arange(len(segments)), intervals + 1)
    first_point = np.concatenate([[0], np.cumsum(intervals + 1)[:-1]])
    step = np.arange(len(segment_of_point)) - first_point[segment_of_point]
    t = (step / intervals[segment_of_point])[:, None]
    return (1.0 - t) * segments[segment_of_point, 0] + t * segments[segment_of_point, 1]


def chamfer_j2j(pred_joints: np.ndarray, ref_joints: np.ndarray, size: float = 1.0) -> float:
    """CD-J2J: symmetric Chamfer distance between two joint sets.

    ``(mean_p min_r |p - r| + mean_r min_p |r - p|) / 2 / size``.

    Parameters
    ----------
    pred_joints : (p, 3) float64 array
    ref_joints : (r, 3) float64 array
    size : float
        Character size the distance is divided by.

    Returns
    -------
    distance : float, in units of ``size``
    """
    pred_joints = checked_joints(pred_joints, "predicted joints")
    ref_joints = checked_joints(ref_joints, "reference joints")
    return symmetric_chamfer(pred_joints, ref_joints) / checked_size(size)


def chamfer_j2b(pred: Skeleton, ref: Skeleton, size: float = 1.0) -> float:
    """CD-J2B: symmetric Chamfer distance from joints to the other's bones.

    ``(mean_p d(p, bones_ref) + mean_r d(r, bones_pred)) / 2 / size`` with
    ``d`` the exact distance to the nearest bone segment (see
    :func:`bone_segments`).

    Parameters
    ----------
    pred, ref : Skeleton
    size : float

    Returns
    -------
    distance : float, in units of ``size``
    """
    pred_to_ref = _joint_bone_distances(pred.joints, ref).min(axis=1).mean()
    ref_to_pred = _joint_bone_distances(ref.joints, pred).min(axis=1).mean()
    return float(pred_to_ref + ref_to_pred) / 2.0 / checked_size(size)


def chamfer_b2b(pred: Skeleton, ref: Skeleton, size: float = 1.0,
                spacing_fraction: float = BONE_SAMPLE_FRACTION) -> float:
    """CD-B2B: symmetric Chamfer distance between points sampled on bones.

    Both skeletons' bones (:func:`bone_segments`) are sampled with
    :func:`sample_bones` every ``spacing_fraction * size`` (RigNet's dense
    sampling), and the CD-J2J formula is applied to the two point sets.
    Longer bones carry more samples and so weigh more.

    Parameters
    ----------
    pred, ref : Skeleton
    size : float
    spacing_fraction : float
        Sample spacing as a share of ``size``.

    Returns
    -------
    distance : float, in units of ``size``
    """
    size = checked_size(size)
    spacing = spacing_fraction * size
    pred_points = sample_bones(bone_segments(pred), spacing)
    ref_points = sample_bones(bone_segments(ref), spacing)
    return symmetric_chamfer(pred_points, ref_points) / size


def evaluate_rig(
    pred: Skeleton,
    ref: Skeleton,
    size: float,
    match_fraction: float = JOINT_MATCH_FRACTION,
    merge_fraction: float = COINCIDENT_JOINT_FRACTION,
) -> dict:
    """All skeleton metrics of a predicted rig against a reference rig.

    Both skeletons are reduced to their deform bones and joints closer than
    ``merge_fraction * size`` are merged, then the metrics are computed.

    Parameters
    ----------
    pred, ref : Skeleton
        In the same space as the character's mesh.
    size : float
        The character's size: the largest side of its rest mesh's bounding
        box in ``eval rig`` (RigNet's unit).
    match_fraction : float
        Joint matching tolerance of IoU/precision/recall
        (:func:`~.joint_matching.joint_iou_precision_recall`), share of ``size``.
    merge_fraction : float
        Coincident-joint tolerance, share of ``size``.

    Returns
    -------
    dict with float values
        ``cd_j2j``, ``cd_j2b``, ``cd_b2b`` (in units of ``size``), ``iou``,
        ``precision``, ``recall`` (with tolerance ``match_fraction * size``)
        and ``tree_edit`` (:func:`~.tree_edit_distance.tree_edit_distance` of the hierarchies,
        unlabelled as in RigNet).
    """
    size = checked_size(size)
    pred = merge_coincident_joints(_deform_skeleton(pred, "predicted"), merge_fraction * size)
    ref = merge_coincident_joints(_deform_skeleton(ref, "reference"), merge_fraction * size)
    overlap = joint_iou_precision_recall(pred.joints, ref.joints, match_fraction * size)
    return {
        "cd_j2j": chamfer_j2j(pred.joints, ref.joints, size),
        "cd_j2b": chamfer_j2b(pred, ref, size),
        "cd_b2b": chamfer_b2b(pred, ref, size),
        "iou": overlap["iou"],
        "precision": overlap["precision"],
        "recall": overlap["recall"],
        "tree_edit": float(tree_edit_distance(pred.parents, ref.parents)),
    }


def _deform_skeleton(skeleton: Skeleton, what: str) -> Skeleton:
    deform = skeleton.deform_subset()
    if deform.bone_count == 0:
        raise InputError(f"The {what} skeleton has no deform bones; mark the bones that move the mesh as Deform.")
    return deform


def _joint_bone_distances(joints: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """(k, s) float64 distance from each joint to each bone segment of ``skeleton``."""
    segments = bone_segments(skeleton)
    return point_segment_distances(joints, segments[:, 0], segments[:, 1])


def symmetric_chamfer(points_a: np.ndarray, points_b: np.ndarray, tree_a: cKDTree | None = None) -> float:
    """Symmetric Chamfer distance ``(mean_a min_b |a - b| + mean_b min_a |b - a|) / 2``.

    Parameters
    ----------
    points_a : (p, 3) float64 array, p >= 1
    points_b : (q, 3) float64 array, q >= 1
    tree_a : cKDTree of ``points_a``, when the caller already built it (one
        set measured against many)

    Returns
    -------
    distance : float, in the units of the points
    """
    a_to_b = cKDTree(points_b).query(points_a)[0].mean()
    b_to_a = (tree_a if tree_a is not None else cKDTree(points_a)).query(points_b)[0].mean()
    return float(a_to_b + b_to_a) / 2.0
