"""Joint matching and the joint IoU, precision and recall it gives
(autorig_addon.core.evaluation.joint_matching)."""

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.evaluation.joint_matching import joint_iou_precision_recall, match_joints
from geometry_fixtures import small_humanoid


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


def test_empty_sides_and_bad_shapes():
    # Both sides empty agree perfectly; one empty side matches nothing.
    joints = small_humanoid().joints
    empty = np.zeros((0, 3))
    assert joint_iou_precision_recall(empty, empty, 0.1) == {"iou": 1.0, "precision": 1.0, "recall": 1.0}
    assert joint_iou_precision_recall(empty, joints, 0.1) == {"iou": 0.0, "precision": 0.0, "recall": 0.0}
    assert joint_iou_precision_recall(joints, empty, 0.1) == {"iou": 0.0, "precision": 0.0, "recall": 0.0}
    np.testing.assert_array_equal(match_joints(joints, empty), np.full(9, -1))
    with pytest.raises(InputError, match=r"The reference joints must be an \(n, 3\) array, got shape \(3,\)"):
        match_joints(joints, np.zeros(3))
    with pytest.raises(InputError, match=r"The predicted joints must be an \(n, 3\) array, got shape \(2, 2\)"):
        joint_iou_precision_recall(np.zeros((2, 2)), joints, 0.1)
