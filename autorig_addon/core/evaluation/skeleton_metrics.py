"""Metrics comparing a predicted skeleton with a reference skeleton.

Follows the skeleton evaluation of RigNet (Xu et al. 2020):

* CD-J2J, CD-J2B, CD-B2B: symmetric Chamfer distances between joints,
  joints and bones, and bones and bones. Each is the mean of the two
  one-way averages ``(mean_a d(a, B) + mean_b d(b, A)) / 2``.
* Joint IoU, precision and recall after a one-to-one (Hungarian) matching of
  predicted to reference joints within a distance tolerance.
* Tree edit distance between the two hierarchies (independent of the order
  in which child bones are listed).

A *bone* here is the segment from a joint's parent to the joint (RigNet's
definition); Blender's tails of leaf bones are not used, because predicted
and artist tails of leaves are arbitrary. A joint without parent or children
counts as a zero-length bone so that it is not ignored.

:func:`evaluate_rig` first keeps only deform bones
(:meth:`Skeleton.deform_subset`) and merges joints at the same place
(:func:`merge_coincident_joints`); it reports distances in units of the
character's size, which callers take as the bounding-box diagonal of the rest
mesh (:func:`~..geometry.bounding_box.character_size`).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..errors import InputError
from ..geometry.bounding_box import checked_size
from ..geometry.segments import point_segment_distances
from ..skeleton.hierarchy import children_lists, descendant_counts, parents_first_order
from ..types import Skeleton

#: Joints closer than this share of the character size are one joint.
COINCIDENT_JOINT_FRACTION = 1e-3

#: A predicted joint matches a reference joint within this share of the
#: character size. RigNet uses half the local shape diameter at the
#: reference joint; for a 1.7 m human in A-pose (bounding-box diagonal about
#: 2 m) this is 5 cm, about half the thickness of an upper arm.
JOINT_MATCH_FRACTION = 0.025

#: Spacing of the points sampled along bones for CD-B2B, as a share of the
#: character size. RigNet steps 0.005 along bones of characters scaled to
#: unit size.
BONE_SAMPLE_FRACTION = 0.005

#: Label of the virtual root that joins the trees of a forest.
_FOREST_ROOT_LABEL = -1


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
    pairs = cKDTree(joints).query_pairs(float(tolerance), output_type="ndarray") if len(joints) else np.zeros((0, 2), int)
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
    pred_joints, ref_joints = _points(pred_joints, "predicted joints"), _points(ref_joints, "reference joints")
    return _symmetric_chamfer(pred_joints, ref_joints) / checked_size(size)


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


def chamfer_b2b(pred: Skeleton, ref: Skeleton, size: float = 1.0, spacing_fraction: float = BONE_SAMPLE_FRACTION) -> float:
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
    return _symmetric_chamfer(pred_points, ref_points) / size




def match_joints(pred_joints: np.ndarray, ref_joints: np.ndarray, tolerance: float | None = None) -> np.ndarray:
    """One-to-one matching of predicted to reference joints (Hungarian).

    Without ``tolerance``: the assignment of ``min(p, r)`` pairs with the
    smallest total distance. With ``tolerance``: among assignments, the one
    with the most pairs at distance ``<= tolerance``, ties broken by the
    smallest total distance of those pairs; pairs farther apart are dropped.

    Parameters
    ----------
    pred_joints : (p, 3) float64 array
    ref_joints : (r, 3) float64 array
    tolerance : float, optional
        Largest distance of a matched pair, in the joints' units.

    Returns
    -------
    matching : (p,) int64 array
        Index of the matched reference joint per predicted joint, -1 if none.
    """
    pred_joints, ref_joints = _points(pred_joints, "predicted joints"), _points(ref_joints, "reference joints")
    matching = np.full(len(pred_joints), -1, dtype=np.int64)
    if not len(pred_joints) or not len(ref_joints):
        return matching
    distance = np.linalg.norm(pred_joints[:, None, :] - ref_joints[None, :, :], axis=2)
    if tolerance is None:
        rows, cols = linear_sum_assignment(distance)
    else:
        within = distance <= tolerance
        # Any pair beyond tolerance costs more than all pairs within it
        # together, so maximising the count of close pairs comes first.
        beyond_cost = (min(distance.shape) + 1) * max(float(tolerance), 0.0) + 1.0
        rows, cols = linear_sum_assignment(np.where(within, distance, beyond_cost))
        keep = within[rows, cols]
        rows, cols = rows[keep], cols[keep]
    matching[rows] = cols
    return matching


def joint_iou_precision_recall(pred_joints: np.ndarray, ref_joints: np.ndarray, tolerance: float) -> dict:
    """Joint IoU, precision and recall after matching within a tolerance.

    With ``t`` the number of pairs of :func:`match_joints` (with
    ``tolerance``): ``iou = t / (p + r - t)``, ``precision = t / p``,
    ``recall = t / r``. An empty side gives 0 (1 when both are empty).

    Parameters
    ----------
    pred_joints : (p, 3) float64 array
    ref_joints : (r, 3) float64 array
    tolerance : float
        In the joints' units (see :data:`JOINT_MATCH_FRACTION`).

    Returns
    -------
    dict with float values ``iou``, ``precision`` and ``recall`` in [0, 1].
    """
    pred_joints, ref_joints = _points(pred_joints, "predicted joints"), _points(ref_joints, "reference joints")
    pred_count, ref_count = len(pred_joints), len(ref_joints)
    if pred_count == 0 and ref_count == 0:
        return {"iou": 1.0, "precision": 1.0, "recall": 1.0}
    matched = int(np.count_nonzero(match_joints(pred_joints, ref_joints, tolerance) >= 0))
    return {
        "iou": matched / (pred_count + ref_count - matched),
        "precision": matched / pred_count if pred_count else 0.0,
        "recall": matched / ref_count if ref_count else 0.0,
    }


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
        (e.g. :func:`match_joints`); required with ``labelled``.
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
        The character's size: bounding-box diagonal of its rest mesh.
    match_fraction : float
        Joint matching tolerance of IoU/precision/recall, share of ``size``.
    merge_fraction : float
        Coincident-joint tolerance, share of ``size``.

    Returns
    -------
    dict with float values
        ``cd_j2j``, ``cd_j2b``, ``cd_b2b`` (in units of ``size``), ``iou``,
        ``precision``, ``recall`` (with tolerance ``match_fraction * size``)
        and ``tree_edit`` (:func:`tree_edit_distance` of the hierarchies,
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


def _deform_skeleton(skeleton: Skeleton, what: str) -> Skeleton:
    deform = skeleton.deform_subset()
    if deform.bone_count == 0:
        raise InputError(f"The {what} skeleton has no deform bones; mark the bones that move the mesh as Deform.")
    return deform


def _joint_bone_distances(joints: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """(k, s) float64 distance from each joint to each bone segment of ``skeleton``."""
    segments = bone_segments(skeleton)
    return point_segment_distances(joints, segments[:, 0], segments[:, 1])


def _symmetric_chamfer(points_a: np.ndarray, points_b: np.ndarray) -> float:
    a_to_b = cKDTree(points_b).query(points_a)[0].mean()
    b_to_a = cKDTree(points_a).query(points_b)[0].mean()
    return float(a_to_b + b_to_a) / 2.0


def _points(points: np.ndarray, what: str) -> np.ndarray:
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise InputError(f"The {what} must be an (n, 3) array, got shape {points.shape}.")
    return points
