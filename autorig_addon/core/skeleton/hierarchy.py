"""The joint hierarchy as a plain parent array: children, roots, orders.

A hierarchy of ``j`` joints is a ``parents`` array: ``parents[k]`` is the
index of joint ``k``'s parent, -1 for a root. Rig files and Blender may
list a child before its parent, so these functions take any order unless
they say otherwise; a :class:`~autorig_addon.core.types.Skeleton` keeps
its joints parents first and is built with :func:`parents_first_order`
and :func:`reindexed_parents`.

Example: ``parents = [1, -1, 1, 0]`` (joint 1 is the root, 0 and 2 its
children, 3 the child of 0) has ``children_lists == [[3], [0, 2], [], []]``,
``root_indices == [1]``, ``parents_first_order == [1, 0, 2, 3]``,
``reindexed_parents(parents, [1, 0, 2, 3]) == [-1, 0, 0, 1]``,
``descendant_counts == [1, 3, 0, 0]``, and keeping joints 1 and 3 only,
``subset_parents(parents, [False, True, False, True]) == [-1, 0]``.
"""

from __future__ import annotations

import heapq

import numpy as np


def _parent_array(parents) -> np.ndarray:
    parents = np.asarray(parents, dtype=np.int64).reshape(-1)
    if np.any((parents < -1) | (parents >= len(parents))):
        raise ValueError("A parent index refers to a joint that does not exist.")
    return parents


def children_lists(parents) -> list[list[int]]:
    """The children of each joint.

    Parameters
    ----------
    parents : (j,) int array, parent index per joint, -1 for roots

    Returns
    -------
    children : list of j lists of int
        ``children[k]`` holds the joints whose parent is ``k``, in index order.
    """
    parents = _parent_array(parents)
    children: list[list[int]] = [[] for _ in range(len(parents))]
    for child, parent in enumerate(parents.tolist()):
        if parent >= 0:
            children[parent].append(child)
    return children


def root_indices(parents) -> np.ndarray:
    """(r,) int64 indices of the joints without a parent, in index order."""
    return np.flatnonzero(_parent_array(parents) < 0)


def parents_first_order(parents) -> np.ndarray:
    """Joint indices ordered so that every parent comes before its children.

    Stable: of the joints whose parent is already placed, the lowest index
    goes next, so a hierarchy that is already parents first keeps its order
    (the result is ``arange(j)``).

    Parameters
    ----------
    parents : (j,) int array, parent index per joint, -1 for roots

    Returns
    -------
    order : (k,) int64 array, ``k <= j``
        ``order[i]`` is the joint placed i-th. Joints that no root reaches
        (those on a cycle, and everything below them) are left out, so
        ``k < j`` tells the caller the parent array has a cycle.
    """
    children = children_lists(parents)
    ready = root_indices(parents).tolist()
    heapq.heapify(ready)
    order = []
    while ready:
        joint = heapq.heappop(ready)
        order.append(joint)
        for child in children[joint]:
            heapq.heappush(ready, child)
    return np.asarray(order, dtype=np.int64)


def reindexed_parents(parents, order) -> np.ndarray:
    """The parent array of the joints taken in ``order``.

    Parameters
    ----------
    parents : (j,) int array, parent index per joint, -1 for roots
    order : (j,) int array, a permutation of ``range(j)`` with parents first
        (:func:`parents_first_order`)

    Returns
    -------
    (j,) int64 array: the parent of joint ``order[i]`` as a position in
    ``order``, -1 for roots; so ``result[i] < i``.
    """
    parents = _parent_array(parents)
    order = np.asarray(order, dtype=np.int64).reshape(-1)
    if len(order) != len(parents) or not np.array_equal(np.sort(order), np.arange(len(parents))):
        raise ValueError("The order must list every joint exactly once.")
    position = np.empty(len(order), dtype=np.int64)
    position[order] = np.arange(len(order))
    ordered_parents = parents[order]
    return np.where(ordered_parents >= 0, position[np.maximum(ordered_parents, 0)], -1)


def descendant_counts(parents) -> np.ndarray:
    """(j,) int64: how many joints lie below each joint (children, their
    children and so on); 0 for a leaf.

    Raises
    ------
    ValueError when the parent array has a cycle.
    """
    parents = _parent_array(parents)
    order = parents_first_order(parents)
    if len(order) != len(parents):
        raise ValueError("The parent array has a cycle.")
    counts = np.zeros(len(parents), dtype=np.int64)
    for joint in order[::-1].tolist():  # children are counted before their parents
        if parents[joint] >= 0:
            counts[parents[joint]] += counts[joint] + 1
    return counts


def subset_parents(parents, keep) -> np.ndarray:
    """The parent array of some of the joints, each linked to its nearest
    kept ancestor (as a skeleton keeps only its deform bones).

    Parameters
    ----------
    parents : (j,) int array, parent index per joint, -1 for roots
    keep : (j,) bool array, the joints to keep

    Returns
    -------
    (k,) int64 array, one entry per kept joint in index order: the
    position among the kept joints of its nearest kept ancestor, -1 when
    none of its ancestors is kept.

    Raises
    ------
    ValueError when the parent array has a cycle.
    """
    parents = _parent_array(parents)
    keep = np.asarray(keep, dtype=bool).reshape(-1)
    if len(keep) != len(parents):
        raise ValueError("keep needs one entry per joint.")
    order = parents_first_order(parents)
    if len(order) != len(parents):
        raise ValueError("The parent array has a cycle.")
    nearest_kept = np.full(len(parents), -1, dtype=np.int64)  # nearest kept proper ancestor
    for joint in order.tolist():  # a parent's answer is known before its children's
        parent = parents[joint]
        if parent >= 0:
            nearest_kept[joint] = parent if keep[parent] else nearest_kept[parent]
    position = np.full(len(parents), -1, dtype=np.int64)
    position[keep] = np.arange(np.count_nonzero(keep))
    kept_ancestors = nearest_kept[keep]
    return np.where(kept_ancestors >= 0, position[np.maximum(kept_ancestors, 0)], -1)


def ancestors(parents, joint: int) -> list[int]:
    """The joints above ``joint``, nearest first (its parent, the parent's parent, ... the root).

    Examples
    --------
    >>> ancestors([-1, 0, 1, 0], 2)
    [1, 0]
    """
    parents = _parent_array(parents)
    found = []
    while parents[joint] >= 0:
        joint = int(parents[joint])
        found.append(joint)
    return found
