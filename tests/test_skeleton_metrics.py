"""Chamfer distances of skeletons, coincident-joint merging and evaluate_rig
(autorig_addon.core.evaluation.skeleton_metrics)."""

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.evaluation.skeleton_metrics import (
    bone_segments,
    chamfer_b2b,
    chamfer_j2b,
    chamfer_j2j,
    evaluate_rig,
    merge_coincident_joints,
    sample_bones,
)
from autorig_addon.core.geometry.bounding_box import bounding_box_diagonal, largest_side
from autorig_addon.core.types import Skeleton
from geometry_fixtures import small_humanoid


def skeleton(joints, parents, deform=None):
    return Skeleton(np.asarray(joints, dtype=float), parents, tuple(f"j{k}" for k in range(len(parents))),
                    deform=deform)


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


def test_eval_rig_unit_is_the_largest_side_not_the_diagonal():
    # A character in a 2 x 1 x 0.5 box (largest side 2, diagonal 2.29) whose
    # two predicted joints are each 0.1 off: CD-J2J = 0.1 / 2 = 0.05 in
    # RigNet's unit, not 0.1 / 2.29 = 0.0436.
    box = np.array([[0.0, 0.0, 0.0], [2.0, 1.0, 0.5]])
    ref = skeleton([[1.0, 0.5, 0.0], [1.0, 0.5, 0.5]], [-1, 0])
    pred = skeleton(ref.joints + [0.1, 0.0, 0.0], [-1, 0])
    assert evaluate_rig(pred, ref, largest_side(box))["cd_j2j"] == pytest.approx(0.05)
    assert 0.1 / bounding_box_diagonal(box) == pytest.approx(0.0436, abs=1e-4)
