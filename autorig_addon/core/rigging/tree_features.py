"""What the bone and root networks see (:mod:`.networks.bones`,
:mod:`.networks.root`): candidate joint pairs and their features, and each
joint's root features.

RigNet's BoneNet scores every joint pair from the joints and a shape code;
ours describes a pair by its offsets, its place on the body and, above all,
by how the solid looks along the segment between the two joints (a bone
runs inside the body; a pair from one leg to the other crosses air),
measured on the same voxel depth as the joint network's input
(:class:`.joint_features.SolidDepth`). Every feature is unchanged by
swapping the pair or mirroring left and right, so the scores of twin pairs
agree. Joints are in the normalised frame (largest side 1).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .joint_features import SolidDepth

#: Each joint's nearest joints whose pairs the bone network scores.
CANDIDATE_NEIGHBOURS = 8
#: Points sampled inside each candidate segment to read the solid's depth.
SEGMENT_SAMPLES = 9
#: A joint this close to the mirror plane is on the midline (share of the
#: largest side).
MIDLINE_TOLERANCE = 0.01
#: Pair feature columns (see :func:`pair_features`) and root feature columns.
PAIR_FEATURES = 19
ROOT_FEATURES = 9
#: Radius within which :func:`root_features` counts a joint's neighbours
#: (share of the largest side).
ROOT_NEIGHBOURHOOD = 0.1


def candidate_pairs(joints: np.ndarray, neighbours: int = CANDIDATE_NEIGHBOURS) -> np.ndarray:
    """(p, 2) int64 pairs ``i < j``, each joint with its nearest joints."""
    count = len(joints)
    if count < 2:
        return np.zeros((0, 2), dtype=np.int64)
    k = min(neighbours, count - 1)
    _, nearest = cKDTree(joints).query(joints, k=k + 1)
    rows = np.repeat(np.arange(count), k)
    others = nearest[:, 1:].reshape(-1)
    pairs = np.sort(np.stack([rows, others], axis=1), axis=1)
    return np.unique(pairs[pairs[:, 0] != pairs[:, 1]], axis=0)


def pair_features(joints: np.ndarray, pairs: np.ndarray, solid: SolidDepth, mirror: np.ndarray) -> np.ndarray:
    """(p, PAIR_FEATURES) float32 description of each pair ``(i, j)``.

    Columns: length; |dx|, |dy|, |dz|; mean |x|, y, z; share of the segment
    inside the solid; least and mean depth along it; least and greatest
    depth of the two joints; least and greatest neighbour rank of each end
    in the other's list; log of the length over each end's nearest-joint
    distance (least, greatest); whether the pair are mirror twins; whether
    both lie on the midline; the least depth along the segment over the
    lesser joint depth (a neck narrowing between them).
    """
    i, j = pairs[:, 0], pairs[:, 1]
    a, b = joints[i], joints[j]
    delta = np.abs(b - a)
    length = np.linalg.norm(b - a, axis=1)
    t = np.linspace(0.0, 1.0, SEGMENT_SAMPLES + 2)[1:-1]
    along = a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]
    depth_along = solid.at(along.reshape(-1, 3)).reshape(len(pairs), SEGMENT_SAMPLES)
    joint_depth = solid.at(joints)
    end_depth = np.stack([joint_depth[i], joint_depth[j]], axis=1)
    rank = _neighbour_ranks(joints, pairs)
    nearest = _nearest_joint_distance(joints)
    ratio = np.log(np.maximum(length[:, None], 1e-9) / np.maximum(np.stack([nearest[i], nearest[j]], axis=1), 1e-9))
    midline = np.abs(joints[:, 0]) <= MIDLINE_TOLERANCE
    least_end = end_depth.min(axis=1)
    columns = [
        length, delta[:, 0], delta[:, 1], delta[:, 2],
        (np.abs(a[:, 0]) + np.abs(b[:, 0])) / 2, (a[:, 1] + b[:, 1]) / 2, (a[:, 2] + b[:, 2]) / 2,
        (depth_along > 0).mean(axis=1), depth_along.min(axis=1), depth_along.mean(axis=1),
        least_end, end_depth.max(axis=1),
        rank.min(axis=1), rank.max(axis=1), ratio.min(axis=1), ratio.max(axis=1),
        (np.asarray(mirror)[i] == j).astype(np.float64), (midline[i] & midline[j]).astype(np.float64),
        np.divide(depth_along.min(axis=1), least_end, out=np.zeros(len(pairs)), where=least_end > 0),
    ]
    return np.stack(columns, axis=1).astype(np.float32)


def root_features(joints: np.ndarray, solid: SolidDepth) -> np.ndarray:
    """(j, ROOT_FEATURES) float32: |x|, y, z, depth, distance to the joints'
    centroid, height and depth over the joints' means, share of joints
    within :data:`ROOT_NEIGHBOURHOOD`, depth rank (0 the deepest)."""
    depth = solid.at(joints)
    centroid = joints.mean(axis=0)
    near = cKDTree(joints).query_ball_point(joints, ROOT_NEIGHBOURHOOD, return_length=True) / max(len(joints), 1)
    depth_rank = np.argsort(np.argsort(-depth)) / max(len(joints) - 1, 1)
    columns = [np.abs(joints[:, 0]), joints[:, 1], joints[:, 2], depth, np.linalg.norm(joints - centroid, axis=1),
               joints[:, 2] - centroid[2], depth - depth.mean(), near, depth_rank]
    return np.stack(columns, axis=1).astype(np.float32)


def _neighbour_ranks(joints: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(p, 2) rank of ``j`` among ``i``'s nearest joints and of ``i`` among
    ``j``'s, 0 the nearest, as a share of :data:`CANDIDATE_NEIGHBOURS`."""
    distances = np.linalg.norm(joints[:, None, :] - joints[None, :, :], axis=2)
    np.fill_diagonal(distances, np.inf)
    # The count of strictly nearer joints: ties (a joint's two twins) share
    # a rank, so mirrored pairs get the same features.
    i, j = pairs[:, 0], pairs[:, 1]
    rank = np.zeros(distances.shape, dtype=np.int64)
    rank[i, j] = (distances[i] < distances[i, j][:, None]).sum(axis=1)
    rank[j, i] = (distances[j] < distances[j, i][:, None]).sum(axis=1)
    return np.stack([rank[i, j], rank[j, i]], axis=1) / CANDIDATE_NEIGHBOURS


def _nearest_joint_distance(joints: np.ndarray) -> np.ndarray:
    if len(joints) < 2:
        return np.zeros(len(joints))
    return cKDTree(joints).query(joints, k=2)[0][:, 1]
