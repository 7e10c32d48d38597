"""Joints to a tree: which pairs are bones, which joint is the root.

RigNet's BoneNet scores every joint pair from the joints and a shape code,
its RootNet picks the root, and a minimum spanning tree over ``-log``
bone probabilities gives the hierarchy. Ours keeps that plan with features
that generalise from a few dozen characters: a pair is described by its
offsets, its place on the body and, above all, by how the solid looks
along the segment between the two joints (a bone runs inside the body; a
pair from one leg to the other crosses air), measured on the same voxel
depth as the joint network's input (:class:`.joint_features.SolidDepth`).
Every feature is unchanged by swapping the pair or mirroring left and
right, so the scores of twin pairs agree.

* :func:`bone_probabilities`: a small MLP over :func:`pair_features` of
  each joint's :data:`CANDIDATE_NEIGHBOURS` nearest joints;
* :func:`root_scores`: a small MLP over :func:`root_features`, softmaxed
  over joints (on a symmetric character only midline joints may be root);
* :func:`spanning_tree`: Kruskal's tree over ``-log p``, taking each edge's
  mirror twin right after it so that left and right get the same bones;
  pairs the network did not score join only parts left apart, shortest first.

Torch twins: :mod:`autorig_addon.core.nn.training.rig_networks`.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..nn.layers import mlp, sigmoid
from .joint_features import SolidDepth
from .joint_network import ACTIVATION

#: Each joint's nearest joints whose pairs the bone network scores.
CANDIDATE_NEIGHBOURS = 8
#: Points sampled inside each candidate segment to read the solid's depth.
SEGMENT_SAMPLES = 9
#: A joint this close to the mirror plane is on the midline (share of the
#: largest side).
MIDLINE_TOLERANCE = 0.01
#: Cost added to pairs the network did not score, so they only join parts
#: the scored pairs leave apart.
UNSCORED_PAIR_COST = 1e3
#: Floor of bone probabilities inside ``-log``.
PROBABILITY_FLOOR = 1e-6
#: Pair feature columns (see :func:`pair_features`) and root feature columns.
PAIR_FEATURES = 19
ROOT_FEATURES = 9
#: Least spread a feature is divided by when standardised.
STD_FLOOR = 1e-4
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


def standardised_mlp(weights: dict, features: np.ndarray) -> np.ndarray:
    """(r,) output of the bone or root network: an MLP on the features
    standardised by the training data's ``input_mean`` and ``input_std``."""
    standard = (features - weights["input_mean"]) / weights["input_std"]
    return mlp(standard, weights, "mlp.", activation=ACTIVATION, activate_last=False)[:, 0]


def bone_probabilities(weights: dict, features: np.ndarray) -> np.ndarray:
    """(p,) probability that each scored pair is a bone."""
    return sigmoid(standardised_mlp(weights, features))


def root_scores(weights: dict, features: np.ndarray) -> np.ndarray:
    """(j,) root score of each joint (higher: more likely the root)."""
    return standardised_mlp(weights, features)


def spanning_tree(joint_count: int, pairs: np.ndarray, probabilities: np.ndarray, mirror: np.ndarray,
                  joints: np.ndarray) -> np.ndarray:
    """(joint_count - 1, 2) edges of the tree (see the module docstring).

    Kruskal's algorithm over ``-log p`` in two passes. The first takes an
    edge only together with its mirror twin, and only when both keep the
    tree a forest, and never joins a joint to its own twin while the
    midline offers a path (left and right then hang from the midline, never
    from each other). The second joins whatever the first left apart,
    cheapest edge first, one edge at a time.
    """
    cost = {tuple(pair): -np.log(max(float(p), PROBABILITY_FLOOR)) for pair, p in zip(pairs.tolist(), probabilities)}
    everything = np.array([(a, b) for a in range(joint_count) for b in range(a + 1, joint_count)], dtype=np.int64)
    lengths = np.linalg.norm(joints[everything[:, 0]] - joints[everything[:, 1]], axis=1) if len(everything) else []
    costs = np.array([cost.get((a, b), UNSCORED_PAIR_COST + length) for (a, b), length in zip(everything.tolist(), lengths)])
    order = everything[np.argsort(costs, kind="stable")].tolist()
    mirror = np.asarray(mirror)
    twin = np.where(mirror >= 0, mirror, np.arange(joint_count))
    has_midline = bool(np.any(mirror < 0)) and bool(np.any(mirror >= 0))
    parent = np.arange(joint_count)

    def find(node: int) -> int:
        while parent[node] != node:
            parent[node] = parent[parent[node]]
            node = parent[node]
        return node

    edges = []
    for a, b in order:
        if has_midline and twin[a] == b:
            continue
        ra, rb, rma, rmb = find(a), find(b), find(twin[a]), find(twin[b])
        if ra == rb:
            continue
        mirrored_is_same = {twin[a], twin[b]} == {a, b}
        if not mirrored_is_same and (rma == rmb or {rma, rmb} == {ra, rb}):
            continue
        parent[ra] = rb
        edges.append((a, b))
        if not mirrored_is_same:
            parent[find(twin[a])] = find(twin[b])
            edges.append((int(twin[a]), int(twin[b])))
    for a, b in order:
        if len(edges) == joint_count - 1:
            break
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[ra] = rb
            edges.append((a, b))
    return np.array(edges, dtype=np.int64).reshape(-1, 2)


def oriented_tree(joint_count: int, edges: np.ndarray, root: int) -> tuple[np.ndarray, np.ndarray]:
    """Parents of the tree hung from ``root``, and a parents-first order.

    Returns
    -------
    order : (j,) int64, joints parents first (breadth first from the root)
    parents : (j,) int64, indexed in the new order, -1 for the root
    """
    neighbours = [[] for _ in range(joint_count)]
    for a, b in edges.tolist():
        neighbours[a].append(b)
        neighbours[b].append(a)
    order, parent_of, seen = [root], {root: -1}, {root}
    position = 0
    while position < len(order):
        node = order[position]
        position += 1
        for other in sorted(neighbours[node]):
            if other not in seen:
                seen.add(other)
                parent_of[other] = node
                order.append(other)
    new_index = {old: new for new, old in enumerate(order)}
    parents = np.array([new_index[parent_of[old]] if parent_of[old] >= 0 else -1 for old in order], dtype=np.int64)
    return np.array(order, dtype=np.int64), parents


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
