"""Joints to a tree: which pairs are bones, which joint is the root.

RigNet's BoneNet scores every joint pair from the joints and a shape code,
its RootNet picks the root, and a minimum spanning tree over ``-log``
bone probabilities gives the hierarchy. Ours keeps that plan with the
features of :mod:`.tree_features`:

* :func:`bone_probabilities`: the bone network (:mod:`.networks.bones`)
  over the pair features of each joint's nearest joints;
* :func:`root_scores`: the root network (:mod:`.networks.root`) over the
  joints' root features, softmaxed over joints (on a symmetric character
  only midline joints may be root);
* :func:`spanning_tree`: Kruskal's tree over ``-log p``, taking each edge's
  mirror twin right after it so that left and right get the same bones;
  pairs the network did not score join only parts left apart, shortest first.
"""

from __future__ import annotations

import numpy as np

from ..nn.numpy_kernels import NUMPY, sigmoid
from ..nn.spec import shipped_weights
from .networks import bones, root

#: Cost added to pairs the network did not score, so they only join parts
#: the scored pairs leave apart.
UNSCORED_PAIR_COST = 1e3
#: Floor of bone probabilities inside ``-log``.
PROBABILITY_FLOOR = 1e-6


def bone_probabilities(features: np.ndarray, weights: dict | None = None) -> np.ndarray:
    """(p,) probability that each scored pair is a bone, from its
    :func:`.tree_features.pair_features`: the bone network with its shipped
    weights, or ``weights`` (a training run's)."""
    params = shipped_weights(bones.SPEC).weights if weights is None else weights
    return sigmoid(bones.SPEC.forward(NUMPY, params, features))


def root_scores(features: np.ndarray, weights: dict | None = None) -> np.ndarray:
    """(j,) root score of each joint (higher: more likely the root), from its
    :func:`.tree_features.root_features`: the root network with its shipped
    weights, or ``weights``."""
    params = shipped_weights(root.SPEC).weights if weights is None else weights
    return root.SPEC.forward(NUMPY, params, features)


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
    costs = np.array([cost.get((a, b), UNSCORED_PAIR_COST + length)
                      for (a, b), length in zip(everything.tolist(), lengths)])
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
