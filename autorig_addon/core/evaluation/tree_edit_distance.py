"""Edit distance between two joint hierarchies, independent of child order.

The skeleton evaluation of RigNet (Xu et al. 2020) compares hierarchies by a
tree edit distance. Here it is Zhang's (1996) constrained edit distance
between unordered forests (:func:`constrained_tree_edit_distance`), so the
order in which child bones are listed plays no part;
:func:`tree_edit_distance` applies it to a predicted and a reference
skeleton's parent arrays, optionally labelled by a joint matching
(:func:`~.joint_matching.match_joints`).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from ..errors import InputError
from ..skeleton.hierarchy import children_lists, descendant_counts, parents_first_order

#: Label of the virtual root that joins the trees of a forest.
_FOREST_ROOT_LABEL = -1


def tree_edit_distance(
    pred_parents: np.ndarray, ref_parents: np.ndarray, matching: np.ndarray | None = None, labelled: bool = False
) -> int:
    """Edit distance between two joint hierarchies, independent of child order.

    The constrained unordered tree edit distance of Zhang (1996): the least
    number of joint insertions and deletions (and, with ``labelled``,
    relabellings) that turns one hierarchy into the other, over mappings
    that keep ancestors ancestors and send disjoint subtrees to disjoint
    subtrees. Sibling order plays no part, so listing bones in another
    order changes nothing. (RigNet uses an ordered distance, APTED, on the
    order the bones are stored in, which does depend on it; both give the
    same result on chains.) Forests (several roots) are joined under one
    virtual root on each side, which costs nothing.

    By default only the hierarchy counts, as in RigNet (zero rename cost):
    identical shapes give 0 and a chain against the same chain with one
    extra leaf gives 1. With ``labelled``, reference joint ``r`` has label
    ``r``, a predicted joint the label of its matched reference joint (or
    one of its own when unmatched), and mapping joints with different
    labels costs 1 as well.

    Parameters
    ----------
    pred_parents : (p,) int64 array
        Parent index per predicted joint, -1 for roots.
    ref_parents : (r,) int64 array
        Parent index per reference joint, -1 for roots.
    matching : (p,) int64 array, optional
        Reference joint matched to each predicted joint, -1 for none
        (e.g. :func:`~.joint_matching.match_joints`); required with ``labelled``.
    labelled : bool
        Whether mapping joints with different labels costs 1.

    Returns
    -------
    distance : int
    """
    pred_parents = np.asarray(pred_parents, dtype=np.int64).reshape(-1)
    ref_parents = np.asarray(ref_parents, dtype=np.int64).reshape(-1)
    if matching is None:
        if labelled:
            raise InputError("A labelled tree edit distance needs the joint matching.")
        matching = np.full(len(pred_parents), -1, dtype=np.int64)
    matching = np.asarray(matching, dtype=np.int64).reshape(-1)
    if len(matching) != len(pred_parents):
        raise InputError(f"The matching has {len(matching)} entries for {len(pred_parents)} predicted joints.")
    if np.any(matching >= len(ref_parents)):
        raise InputError("The matching refers to a reference joint that does not exist.")
    matched = matching[matching >= 0]
    if len(np.unique(matched)) != len(matched):
        raise InputError("The matching uses a reference joint twice; it must be one-to-one.")
    # Unmatched predicted joints get labels no reference joint has: -2, -3, ...
    pred_labels = np.where(matching >= 0, matching, -2 - np.arange(len(matching)))
    ref_labels = np.arange(len(ref_parents))
    return constrained_tree_edit_distance(
        pred_parents, pred_labels, ref_parents, ref_labels, relabel_cost=int(labelled)
    )


def constrained_tree_edit_distance(
    parents_a: np.ndarray,
    labels_a: np.ndarray,
    parents_b: np.ndarray,
    labels_b: np.ndarray,
    relabel_cost: int = 1,
) -> int:
    """Zhang's (1996) constrained edit distance between unordered labelled forests.

    Costs: insert 1, delete 1, relabel ``relabel_cost`` when the labels
    differ, else 0. Each forest is joined under a virtual root (same label
    on both sides). Subtree pairs are solved children first; the children of
    two joints are paired by a minimum-cost assignment
    (``scipy.optimize.linear_sum_assignment``). Time
    ``O(|A| |B| (deg A + deg B) log(deg A + deg B))``.

    Parameters
    ----------
    parents_a, parents_b : (n,) int64 array
        Parent per node, -1 for roots; any node order, no cycles.
    labels_a, labels_b : (n,) int64 array
        Node labels, never equal to -1 (reserved for the virtual root).
    relabel_cost : int
        Cost of mapping a node onto one with another label (0 ignores labels).

    Returns
    -------
    distance : int
    """
    parents_a, labels_a = _under_virtual_root(parents_a, labels_a)
    parents_b, labels_b = _under_virtual_root(parents_b, labels_b)
    children_a, children_b = children_lists(parents_a), children_lists(parents_b)
    # Children before parents, so the virtual root comes last.
    order_a, order_b = parents_first_order(parents_a)[::-1].tolist(), parents_first_order(parents_b)[::-1].tolist()
    size_a, size_b = descendant_counts(parents_a) + 1, descendant_counts(parents_b) + 1
    # tree[i, j]: distance between the subtrees at i and j; forest[i, j]:
    # between their forests of children.
    tree = np.zeros((len(children_a), len(children_b)), dtype=np.int64)
    forest = np.zeros_like(tree)
    for i in order_a:
        kids_a = children_a[i]
        for j in order_b:
            kids_b = children_b[j]
            forest[i, j] = _forest_distance(i, j, kids_a, kids_b, tree, forest, size_a, size_b)
            best = forest[i, j] + relabel_cost * int(labels_a[i] != labels_b[j])
            if kids_b:
                # j is inserted; the subtree at i goes into one child's subtree.
                best = min(best, size_b[j] + min(tree[i, t] - size_b[t] for t in kids_b))
            if kids_a:
                best = min(best, size_a[i] + min(tree[s, j] - size_a[s] for s in kids_a))
            tree[i, j] = best
    return int(tree[order_a[-1], order_b[-1]])


def _forest_distance(i, j, kids_a, kids_b, tree, forest, size_a, size_b) -> int:
    """Constrained distance between the forests of children of ``i`` and ``j``."""
    inserted = size_b[j] - 1
    deleted = size_a[i] - 1
    if not kids_a or not kids_b:
        return inserted + deleted
    # The whole forest of i goes into the forest of one child of j (the
    # rest of j's forest is inserted), or the other way round.
    best = min(
        inserted + min(forest[i, t] - (size_b[t] - 1) for t in kids_b),
        deleted + min(forest[s, j] - (size_a[s] - 1) for s in kids_a),
    )
    # Or the children are paired one to one; an unpaired subtree is deleted
    # or inserted whole. Pairing costs tree distance minus that, never > 0.
    saving = tree[np.ix_(kids_a, kids_b)] - size_a[kids_a][:, None] - size_b[kids_b][None, :]
    rows, cols = linear_sum_assignment(saving)
    return int(min(best, inserted + deleted + saving[rows, cols].sum()))


def _under_virtual_root(parents: np.ndarray, labels: np.ndarray) -> tuple:
    """A forest joined under a virtual root, for tree distances.

    Returns ``(parents, labels)`` with one more node, the virtual root (index
    ``n``, label :data:`_FOREST_ROOT_LABEL`), parent of the former roots.
    """
    parents = np.asarray(parents, dtype=np.int64).reshape(-1)
    labels = np.asarray(labels, dtype=np.int64).reshape(-1)
    count = len(parents)
    if len(labels) != count:
        raise InputError("Each node needs one parent and one label.")
    if np.any((parents < -1) | (parents >= count)):
        raise InputError("A parent index refers to a node that does not exist.")
    if np.any(labels == _FOREST_ROOT_LABEL):
        raise InputError(f"Label {_FOREST_ROOT_LABEL} is reserved for the virtual root.")
    rooted = np.append(np.where(parents < 0, count, parents), -1)
    if len(parents_first_order(rooted)) != count + 1:
        raise InputError("The parent array does not describe a forest (it has a cycle).")
    return rooted, np.append(labels, _FOREST_ROOT_LABEL)
