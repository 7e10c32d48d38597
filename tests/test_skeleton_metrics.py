import itertools

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.evaluation.skeleton_metrics import (
    bone_segments,
    chamfer_b2b,
    chamfer_j2b,
    chamfer_j2j,
    constrained_tree_edit_distance,
    evaluate_rig,
    joint_iou_precision_recall,
    match_joints,
    merge_coincident_joints,
    sample_bones,
    tree_edit_distance,
)
from autorig_addon.core.types import Skeleton


def skeleton(joints, parents, deform=None):
    return Skeleton(np.asarray(joints, dtype=float), parents, tuple(f"j{k}" for k in range(len(parents))), deform=deform)


def small_humanoid():
    """Hips, spine, head, two arms and two legs; size 2 when scaled by 1."""
    joints = [
        [0.0, 0.0, 1.0],   # 0 hips
        [0.0, 0.0, 1.4],   # 1 chest
        [0.0, 0.0, 1.8],   # 2 head
        [0.3, 0.0, 1.4],   # 3 upper arm L
        [0.6, 0.0, 1.4],   # 4 forearm L
        [-0.3, 0.0, 1.4],  # 5 upper arm R
        [-0.6, 0.0, 1.4],  # 6 forearm R
        [0.1, 0.0, 0.5],   # 7 shin L
        [-0.1, 0.0, 0.5],  # 8 shin R
    ]
    return skeleton(joints, [-1, 0, 1, 1, 3, 1, 5, 0, 0])


# --- Chamfer distances ---------------------------------------------------


def test_j2j_two_joints_shifted():
    ref = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert chamfer_j2j(ref + [0.1, 0.0, 0.0], ref) == pytest.approx(0.1)


def test_j2j_asymmetric_sets_and_size():
    # pred -> ref: (0 + 1) / 2 = 0.5; ref -> pred: 0. Mean 0.25, size 2.
    pred = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    ref = np.array([[0.0, 0.0, 0.0]])
    assert chamfer_j2j(pred, ref) == pytest.approx(0.25)
    assert chamfer_j2j(pred, ref, size=2.0) == pytest.approx(0.125)


def test_j2b_joints_half_above_a_horizontal_bone():
    ref = skeleton([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], [-1, 0])
    pred = skeleton([[0.0, 0.0, 0.5], [2.0, 0.0, 0.5]], [-1, 0])
    assert chamfer_j2b(pred, ref) == pytest.approx(0.5)


def test_j2b_single_joint_against_bone():
    # pred is one joint at (1, 0, 0.5): 0.5 above the middle of the ref
    # bone. Ref joints (0,0,0), (2,0,0) are sqrt(1 + 0.25) from it.
    ref = skeleton([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], [-1, 0])
    pred = skeleton([[1.0, 0.0, 0.5]], [-1])
    assert chamfer_j2b(pred, ref) == pytest.approx((0.5 + np.sqrt(1.25)) / 2.0)
    assert chamfer_j2b(pred, ref, size=4.0) == pytest.approx((0.5 + np.sqrt(1.25)) / 8.0)



def test_bone_segments_run_parent_to_child_and_keep_lone_joints():
    bones = skeleton([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [7.0, 7.0, 7.0]], [-1, 0, 1, -1])
    segments = bone_segments(bones)
    np.testing.assert_array_equal(
        segments, [[[0, 0, 0], [1, 0, 0]], [[1, 0, 0], [1, 1, 0]], [[7, 7, 7], [7, 7, 7]]]
    )


def test_sample_bones_spacing_and_ends():
    points = sample_bones(np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]]), 0.3)
    # ceil(1 / 0.3) = 4 intervals of 0.25.
    np.testing.assert_allclose(points[:, 0], [0.0, 0.25, 0.5, 0.75, 1.0])
    np.testing.assert_allclose(points[:, 1:], 0.0)


def test_b2b_parallel_bones():
    ref = skeleton([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [-1, 0])
    pred = skeleton([[0.0, 0.1, 0.0], [1.0, 0.1, 0.0]], [-1, 0])
    assert chamfer_b2b(pred, ref) == pytest.approx(0.1)
    assert chamfer_b2b(pred, ref, size=0.5) == pytest.approx(0.2)


def test_b2b_half_length_bone_approximates_the_integral():
    # pred covers [0, 0.5] of the ref bone [0, 1]: pred -> ref is 0; ref ->
    # pred averages max(0, x - 0.5) over x in [0, 1] = 0.125 for dense
    # samples. B2B = 0.125 / 2. Sampled every 0.005 exactly:
    # sum_{m=0}^{100} (m / 200) / 201 / 2 = 25.25 / 201 / 2.
    ref = skeleton([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [-1, 0])
    pred = skeleton([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]], [-1, 0])
    assert chamfer_b2b(pred, ref) == pytest.approx(25.25 / 201.0 / 2.0, abs=1e-9)
    assert chamfer_b2b(pred, ref) == pytest.approx(0.0625, abs=1e-3)


# --- Matching, IoU, precision, recall ------------------------------------


def test_iou_precision_recall_hand_computed():
    # 2 of 4 predicted joints lie within 0.1 of 2 of the 3 reference joints:
    # precision 2/4, recall 2/3, IoU 2 / (4 + 3 - 2) = 0.4.
    ref = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    pred = np.array([[0.05, 0.0, 0.0], [1.0, 0.08, 0.0], [2.0, 0.5, 0.0], [9.0, 0.0, 0.0]])
    result = joint_iou_precision_recall(pred, ref, tolerance=0.1)
    assert result["precision"] == pytest.approx(0.5)
    assert result["recall"] == pytest.approx(2.0 / 3.0)
    assert result["iou"] == pytest.approx(0.4)


def test_identical_joints_give_perfect_overlap():
    joints = small_humanoid().joints
    assert joint_iou_precision_recall(joints, joints[::-1], 0.01) == {"iou": 1.0, "precision": 1.0, "recall": 1.0}


def test_matching_maximises_pairs_within_tolerance():
    # p1 sits on B and 1 from A; p2 is 1 from B and sqrt(3) from A. The
    # smallest total distance pairs p1-B (0) and p2-A (1.73 > tolerance):
    # one match. Pairing p1-A and p2-B (1 + 1) keeps both within 1.01.
    ref = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    pred = np.array([[1.0, 0.0, 0.0], [1.5, np.sqrt(0.75), 0.0]])
    np.testing.assert_array_equal(match_joints(pred, ref), [1, 0])
    np.testing.assert_array_equal(match_joints(pred, ref, tolerance=1.01), [0, 1])
    assert joint_iou_precision_recall(pred, ref, 1.01)["recall"] == pytest.approx(1.0)


def test_matching_drops_pairs_beyond_tolerance():
    ref = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    pred = np.array([[0.0, 0.0, 0.05], [3.0, 0.0, 0.0], [1.0, 0.02, 0.0]])
    np.testing.assert_array_equal(match_joints(pred, ref, tolerance=0.1), [0, -1, 1])
    np.testing.assert_array_equal(match_joints(pred, ref), [0, -1, 1])


# --- Tree edit distance --------------------------------------------------


def test_tree_edit_identical_chains():
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1], [0, 1, 2]) == 0


def test_tree_edit_chain_with_extra_leaf():
    # pred is the reference chain plus an unmatched leaf under joint 1.
    assert tree_edit_distance([-1, 0, 1, 1], [-1, 0, 1], [0, 1, 2, -1]) == 1
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1, 2], [0, 1, 2]) == 1


def test_tree_edit_reparented_joint_costs_two():
    # Reference: 1 and 2 both children of 0. Prediction: chain 0-1-2.
    # No mapping keeps 1 above 2 and both matched: delete and re-insert 2.
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 0], [0, 1, 2]) == 2


def test_tree_edit_relabels_only_when_labelled():
    # Same shape, but predicted joint 2 matched no reference joint: the
    # hierarchy alone (RigNet) costs nothing, the labelled variant 1.
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1], [0, 1, -1]) == 0
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1], [0, 1, -1], labelled=True) == 1
    assert tree_edit_distance([-1, 0, 1], [-1, 0, 1], [0, 1, 2], labelled=True) == 0


def test_tree_edit_ignores_sibling_order():
    # Reference: root with a leaf (1) and a joint with a child (2 -> 3).
    # Prediction: the same shape with the children listed the other way
    # round (1 -> 3, 2 leaf). An ordered distance would give 2.
    assert tree_edit_distance([-1, 0, 0, 1], [-1, 0, 0, 2]) == 0
    assert tree_edit_distance([-1, 0, 0, 1], [-1, 0, 0, 2], [0, 2, 1, 3], labelled=True) == 0


def test_tree_edit_star_against_chain():
    # r(a, b, c) vs r(a(b(c))): leaves of the star are unrelated, nodes of
    # the chain all related, so besides the roots only one joint can map:
    # 2 deletions + 2 insertions.
    assert tree_edit_distance([-1, 0, 0, 0], [-1, 0, 1, 2]) == 4


def test_tree_edit_forests_join_under_a_free_root():
    # Two roots each side, same structure: 0; one root short: 1.
    assert tree_edit_distance([-1, -1, 1], [-1, -1, 1]) == 0
    assert tree_edit_distance([-1, 0], [-1, -1, 1]) == 1


def test_tree_edit_labelled_paper_example():
    # Zhang & Shasha (1989): f(d(a, c(b)), e) vs f(c(d(a, b)), e) = 2:
    # delete c under d, insert c above d. Labels a..f = 0..5.
    #            f  d  a  c  b  e
    parents_1 = [-1, 0, 1, 1, 3, 0]
    labels_1 = [5, 3, 0, 2, 1, 4]
    #            f  c  d  a  b  e
    parents_2 = [-1, 0, 1, 2, 2, 0]
    labels_2 = [5, 2, 3, 0, 1, 4]
    assert constrained_tree_edit_distance(parents_1, labels_1, parents_2, labels_2) == 2
    assert constrained_tree_edit_distance(parents_1, labels_1, parents_2, labels_2, relabel_cost=0) == 2


def _ancestors(parents):
    result = []
    for node in range(len(parents)):
        chain, parent = set(), parents[node]
        while parent >= 0:
            chain.add(parent)
            parent = parents[parent]
        result.append(chain)
    return result


def _lowest_common_ancestor(ancestors, a, b):
    common = (ancestors[a] | {a}) & (ancestors[b] | {b})
    return max(common, key=lambda node: len(ancestors[node]))


def _brute_force_distance(parents_a, labels_a, parents_b, labels_b):
    """Cheapest constrained mapping by enumerating all of them (tiny trees).

    Zhang (1996): a mapping keeps ancestry, and lca(t1, t2) is a proper
    ancestor of t3 exactly when lca(s1, s2) is one of s3.
    """
    trees = []
    for parents, labels in ((parents_a, labels_a), (parents_b, labels_b)):
        count = len(parents)
        joined = [count if p < 0 else p for p in parents] + [-1]
        trees.append((joined, list(labels) + [-1], _ancestors(joined)))
    (par_a, lab_a, anc_a), (par_b, lab_b, anc_b) = trees
    best = len(par_a) + len(par_b)
    for k in range(min(len(par_a), len(par_b)) + 1):
        for nodes_a in itertools.combinations(range(len(par_a)), k):
            for nodes_b in itertools.permutations(range(len(par_b)), k):
                pairs = list(zip(nodes_a, nodes_b))
                if any(
                    (t1 in anc_a[t2]) != (s1 in anc_b[s2]) for (t1, s1), (t2, s2) in itertools.permutations(pairs, 2)
                ):
                    continue
                if any(
                    (_lowest_common_ancestor(anc_a, t1, t2) in anc_a[t3])
                    != (_lowest_common_ancestor(anc_b, s1, s2) in anc_b[s3])
                    for (t1, s1), (t2, s2), (t3, s3) in itertools.permutations(pairs, 3)
                ):
                    continue
                relabels = sum(lab_a[t] != lab_b[s] for t, s in pairs)
                best = min(best, len(par_a) + len(par_b) - 2 * k + relabels)
    return best


def test_constrained_distance_agrees_with_brute_force():
    rng = np.random.default_rng(4)
    for _ in range(40):
        trees = []
        for _ in range(2):
            count = int(rng.integers(1, 5))
            parents = [-1] + [int(rng.integers(-1, j)) for j in range(1, count)]
            trees.append((parents, [int(x) for x in rng.integers(0, 3, count)]))
        (parents_a, labels_a), (parents_b, labels_b) = trees
        expected = _brute_force_distance(parents_a, labels_a, parents_b, labels_b)
        assert constrained_tree_edit_distance(parents_a, labels_a, parents_b, labels_b) == expected


def test_tree_edit_is_invariant_to_joint_order():
    # A random 30-joint hierarchy against itself with indices shuffled
    # (parents kept first): 0; against itself minus a leaf: 1.
    rng = np.random.default_rng(9)
    parents = np.array([-1] + [int(rng.integers(0, j)) for j in range(1, 30)])
    depth = np.zeros(30, dtype=int)
    for j in range(1, 30):
        depth[j] = depth[parents[j]] + 1
    permutation = np.lexsort((rng.random(30), depth))  # parents stay before children
    new_index = np.empty(30, dtype=int)
    new_index[permutation] = np.arange(30)
    shuffled = np.where(parents[permutation] >= 0, new_index[parents[permutation]], -1)
    assert tree_edit_distance(shuffled, parents) == 0
    leaf = int(np.setdiff1d(np.arange(30), parents)[0])
    keep = np.delete(np.arange(30), leaf)
    old_to_new = -np.ones(30, dtype=int)
    old_to_new[keep] = np.arange(29)
    pruned = np.where(parents[keep] >= 0, old_to_new[parents[keep]], -1)
    assert tree_edit_distance(pruned, parents) == 1


def test_tree_edit_rejects_bad_matching():
    with pytest.raises(InputError, match="The matching uses a reference joint twice; it must be one-to-one"):
        tree_edit_distance([-1, 0], [-1, 0], [0, 0])
    with pytest.raises(InputError, match="The matching has 1 entries for 2 predicted joints"):
        tree_edit_distance([-1, 0], [-1, 0], [0])
    with pytest.raises(InputError, match="The matching refers to a reference joint that does not exist"):
        tree_edit_distance([-1, 0], [-1, 0], [0, 2])
    with pytest.raises(InputError, match="A labelled tree edit distance needs the joint matching"):
        tree_edit_distance([-1, 0], [-1, 0], labelled=True)


# --- Merging and the full evaluation -------------------------------------


def test_merge_coincident_parent_and_child():
    # Joint 1 sits on its parent 0; its children 2 and 3 move up to the
    # merged joint.
    bones = skeleton([[0.0, 0.0, 0.0], [0.0, 0.0, 1e-6], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]], [-1, 0, 1, 1])
    merged = merge_coincident_joints(bones, 1e-3)
    np.testing.assert_array_equal(merged.parents, [-1, 0, 0])
    np.testing.assert_allclose(merged.joints, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    assert merged.names == ("j0", "j2", "j3")


def test_merge_coincident_siblings():
    # Siblings 1 and 2 at one place: one joint whose children are 3 and 4.
    bones = skeleton(
        [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]], [-1, 0, 0, 1, 2]
    )
    merged = merge_coincident_joints(bones, 1e-3)
    np.testing.assert_array_equal(merged.parents, [-1, 0, 1, 1])
    np.testing.assert_allclose(merged.joints[1], [0.0, 0.0, 1.0])
    # Nothing coincides in the humanoid: it comes back whole.
    assert merge_coincident_joints(small_humanoid(), 1e-3).bone_count == 9


def test_evaluate_rig_identical():
    result = evaluate_rig(small_humanoid(), small_humanoid(), size=2.0)
    assert result == {
        "cd_j2j": 0.0, "cd_j2b": 0.0, "cd_b2b": 0.0, "iou": 1.0, "precision": 1.0, "recall": 1.0, "tree_edit": 0.0,
    }


def test_evaluate_rig_shifted_skeleton():
    # Every joint 0.1 off along y (no two ref joints within 0.1 of a shifted
    # one): J2J = J2B = B2B = 0.1 / size 2 = 0.05. Tolerance 0.025 * 2 =
    # 0.05 < 0.1: nothing matches. The closest matching is still the
    # identity, so the hierarchy costs nothing.
    ref = small_humanoid()
    pred = skeleton(ref.joints + [0.0, 0.1, 0.0], ref.parents)
    result = evaluate_rig(pred, ref, size=2.0)
    assert result["cd_j2j"] == pytest.approx(0.05)
    assert result["cd_j2b"] == pytest.approx(0.05)
    assert result["cd_b2b"] == pytest.approx(0.05)
    assert (result["iou"], result["precision"], result["recall"]) == (0.0, 0.0, 0.0)
    assert result["tree_edit"] == 0.0
    loose = evaluate_rig(pred, ref, size=2.0, match_fraction=0.06)
    assert (loose["iou"], loose["precision"], loose["recall"]) == (1.0, 1.0, 1.0)


def test_evaluate_rig_ignores_non_deform_bones_and_duplicate_joints():
    ref = small_humanoid()
    # A control bone far away (not deforming) and a twist bone at the same
    # place as the left forearm joint, child of it.
    joints = np.vstack([ref.joints, [[5.0, 5.0, 5.0], [0.6, 0.0, 1.4]]])
    parents = np.concatenate([ref.parents, [-1, 4]])
    deform = np.concatenate([np.ones(ref.bone_count, bool), [False, True]])
    pred = skeleton(joints, parents, deform)
    assert evaluate_rig(pred, ref, size=2.0) == evaluate_rig(ref, ref, size=2.0)


def test_evaluate_rig_extra_leaf_joint():
    # One extra leaf beyond the left hand, 0.2 further out. J2J: pred -> ref
    # mean = 0.2 / 10 joints, ref -> pred 0: (0.02 + 0) / 2 / size 2 = 0.005.
    # Precision 9/10, recall 1, IoU 9/10, one insertion in the tree.
    ref = small_humanoid()
    pred = skeleton(np.vstack([ref.joints, [[0.8, 0.0, 1.4]]]), np.concatenate([ref.parents, [4]]))
    result = evaluate_rig(pred, ref, size=2.0)
    assert result["cd_j2j"] == pytest.approx(0.005)
    assert result["precision"] == pytest.approx(0.9)
    assert result["recall"] == pytest.approx(1.0)
    assert result["iou"] == pytest.approx(0.9)
    assert result["tree_edit"] == 1.0


def test_evaluate_rig_rejects_bad_input():
    with pytest.raises(InputError, match="The character size must be a positive length, got 0.0"):
        evaluate_rig(small_humanoid(), small_humanoid(), size=0.0)
    with pytest.raises(InputError, match="The character size must be a positive length, got nan"):
        chamfer_j2j(np.zeros((1, 3)), np.zeros((1, 3)), size=float("nan"))
    no_deform = skeleton([[0.0, 0.0, 0.0]], [-1], deform=[False])
    with pytest.raises(InputError, match="The predicted skeleton has no deform bones; mark the bones that move"):
        evaluate_rig(no_deform, small_humanoid(), size=2.0)
    with pytest.raises(InputError, match=r"The predicted joints must be an \(n, 3\) array, got shape \(2, 2\)"):
        chamfer_j2j(np.zeros((2, 2)), np.zeros((1, 3)))
    with pytest.raises(InputError, match="The bone sample spacing must be positive, got 0.0"):
        sample_bones(np.zeros((1, 2, 3)), 0.0)
