"""Skin metrics (autorig_addon.core.evaluation.skin_metrics): what ``eval skin`` prints."""

import math

import numpy as np
import pytest

from autorig_addon.core.errors import InputError
from autorig_addon.core.evaluation.skin_metrics import (
    evaluate_skin,
    evaluate_transfer,
    influence_precision_recall,
    skin_l1,
)
from autorig_addon.core.skeleton.posing import axis_angle_matrices, random_poses
from autorig_addon.core.types import Skeleton, Weights


def two_root_skeleton():
    """Two unrelated roots: one at the origin, one at (5, 0, 0)."""
    return Skeleton([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]], [-1, -1], ("turning", "still"))


def quarter_turn_of_first_bone():
    pose = np.broadcast_to(np.eye(3), (1, 2, 3, 3)).copy()
    pose[0, 0] = axis_angle_matrices([[0.0, 0.0, 1.0]], [np.pi / 2])[0]
    return pose


def test_identical_weights_score_perfectly():
    weights = np.array([[1.0, 0.0, 0.0], [0.2, 0.8, 0.0], [0.0, 0.5, 0.5]])
    assert skin_l1(weights, weights) == 0.0
    assert influence_precision_recall(weights, weights) == {"precision": 1.0, "recall": 1.0}


def test_l1_hand_computed():
    # Row 0: |1-0| + |0-1| = 2; row 1: |0.5-0.5| + |0.5-0.5| = 0; row 2:
    # |0.7-1| + |0.3-0| = 0.6. Mean = 2.6 / 3.
    pred = np.array([[1.0, 0.0], [0.5, 0.5], [0.7, 0.3]])
    ref = np.array([[0.0, 1.0], [0.5, 0.5], [1.0, 0.0]])
    assert skin_l1(pred, ref) == pytest.approx(2.6 / 3.0)


def test_precision_recall_hand_computed():
    # Influences: pred {0,1}, {0}; ref {0}, {0}. Common 2, predicted 3,
    # reference 2: precision 2/3, recall 1.
    pred = np.array([[0.7, 0.3, 0.0], [1.0, 0.0, 0.0]])
    ref = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    result = influence_precision_recall(pred, ref)
    assert result["precision"] == pytest.approx(2.0 / 3.0)
    assert result["recall"] == pytest.approx(1.0)
    swapped = influence_precision_recall(ref, pred)
    assert swapped["precision"] == pytest.approx(1.0)
    assert swapped["recall"] == pytest.approx(2.0 / 3.0)


def test_precision_recall_pools_counts_over_vertices():
    # Vertex 0: pred {0,1,2,3} vs ref {0}: 1 of 4 right. Vertex 1: pred {0}
    # vs ref {0}. Pooled precision = (1 + 1) / (4 + 1) = 0.4 (a per-vertex
    # average would give (0.25 + 1) / 2 = 0.625).
    pred = np.array([[0.25, 0.25, 0.25, 0.25], [1.0, 0.0, 0.0, 0.0]])
    ref = np.array([[1.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
    assert influence_precision_recall(pred, ref)["precision"] == pytest.approx(0.4)


def test_influence_threshold_is_strict():
    # 1e-4 is not an influence, 2e-4 is.
    ref = np.array([[1.0, 0.0]])
    at_threshold = influence_precision_recall(np.array([[1.0 - 1e-4, 1e-4]]), ref)
    above = influence_precision_recall(np.array([[1.0 - 2e-4, 2e-4]]), ref)
    assert at_threshold["precision"] == 1.0
    assert above["precision"] == pytest.approx(0.5)
    assert influence_precision_recall(np.array([[1.0 - 2e-4, 2e-4]]), ref, threshold=0.01)["precision"] == 1.0


def test_empty_prediction_has_zero_precision_and_recall():
    result = influence_precision_recall(np.zeros((2, 2)), np.array([[1.0, 0.0], [0.0, 1.0]]))
    assert result == {"precision": 0.0, "recall": 0.0}


def test_mismatched_shapes_are_rejected():
    with pytest.raises(InputError, match=r"Predicted weights \(2, 3\) and reference weights \(2, 2\) must both be"):
        skin_l1(np.zeros((2, 3)), np.zeros((2, 2)))
    with pytest.raises(InputError, match=r"Predicted weights \(3, 2\) and reference weights \(2, 2\) must both be"):
        influence_precision_recall(np.zeros((3, 2)), np.zeros((2, 2)))


def test_evaluate_skin_identical_weights():
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [4.0, 1.0, 1.0]])
    weights = np.array([[1.0, 0.0], [0.4, 0.6], [0.0, 1.0]])
    result = evaluate_skin(vertices, weights, weights, skeleton)
    assert result == {
        "l1": 0.0, "precision": 1.0, "recall": 1.0, "deform_mean": 0.0, "deform_max": 0.0, "unweighted": 0,
    }


def test_evaluate_skin_hand_computed():
    # Vertex (2,0,0): ref on the turning bone -> (0,2,0); pred on the still
    # bone -> (2,0,0): distance 2*sqrt(2). Vertex (0,0,0) is on the axis and
    # correct. Size = bbox diagonal 2. L1 = (2 + 0) / 2 = 1. Influences:
    # pred {1}, {0}; ref {0}, {0}: precision 1/2, recall 1/2.
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    ref = np.array([[1.0, 0.0], [1.0, 0.0]])
    pred = np.array([[0.0, 1.0], [1.0, 0.0]])
    result = evaluate_skin(vertices, pred, ref, skeleton, quarter_turn_of_first_bone())
    assert result["l1"] == pytest.approx(1.0)
    assert result["precision"] == pytest.approx(0.5)
    assert result["recall"] == pytest.approx(0.5)
    assert result["deform_mean"] == pytest.approx(np.sqrt(2.0) / 2.0)
    assert result["deform_max"] == pytest.approx(np.sqrt(2.0))


def test_evaluate_skin_matches_named_weights_by_bone():
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    ref = Weights(np.array([[1.0, 0.0], [1.0, 0.0]]), ("turning", "still"))
    pred = Weights(np.array([[1.0, 0.0], [0.0, 1.0]]), ("still", "turning"))
    result = evaluate_skin(vertices, pred, ref, skeleton, quarter_turn_of_first_bone())
    assert result["l1"] == pytest.approx(1.0)
    assert result["deform_max"] == pytest.approx(np.sqrt(2.0))


def test_evaluate_skin_uses_only_deform_bones():
    # A non-deform control bone between the two: weights have 2 columns.
    skeleton = Skeleton(
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [5.0, 0.0, 0.0]], [-1, -1, -1], ("turning", "control", "still"),
        deform=[True, False, True],
    )
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    ref = np.array([[1.0, 0.0], [1.0, 0.0]])
    pred = np.array([[0.0, 1.0], [1.0, 0.0]])
    result = evaluate_skin(vertices, pred, ref, skeleton, quarter_turn_of_first_bone())
    assert result["deform_max"] == pytest.approx(np.sqrt(2.0))
    with pytest.raises(InputError, match=r"The predicted weights have shape \(2, 3\) but the mesh has 2 vertices "
                                         r"and the skeleton 2 deform bones"):
        evaluate_skin(vertices, np.ones((2, 3)) / 3, np.ones((2, 3)) / 3, skeleton)


def test_evaluate_skin_worked_example():
    # Bone 'turning' (head at the origin) turns a quarter about z; 'still'
    # stays. Rows are normalised before anything is measured.
    #
    # vertex    rest     ref       pred (normalised)   ref posed   pred posed      distance    L1
    # 0         (2,0,0)  (1, 0)    (0, 0) unweighted   (0,2,0)     (2,0,0) rest    2 sqrt(2)   1
    # 1         (0,0,0)  (1, 0)    (0.5, 0.5)          (0,0,0)     (0,0,0)         0           1
    # 2         (0,1,0)  (0, 1)    (0.25, 0.75)        (0,1,0)     (-0.25,0.75,0)  sqrt(2)/4   0.5
    # 3         (4,0,0)  (0, 0)    (1, 0)              not scored: the reference leaves it unweighted
    #
    # Vertex 2 posed with the prediction: 0.25 (-1,0,0) + 0.75 (0,1,0).
    # L1 = (1 + 1 + 0.5) / 3. Influences pred {}, {0,1}, {0,1}; ref {0},
    # {0}, {1}: 2 in common of 4 predicted and 3 reference.
    # The size is the bounding-box diagonal of all four vertices (vertex 3
    # included): |(4, 1, 0)| = sqrt(17).
    # deform_mean = (2 sqrt(2) + 0 + sqrt(2)/4) / 3 / sqrt(17) = 0.75 sqrt(2 / 17),
    # deform_max = 2 sqrt(2) / sqrt(17).
    skeleton = two_root_skeleton()
    vertices = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [4.0, 0.0, 0.0]])
    ref = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    pred = np.array([[0.0, 0.0], [0.2, 0.2], [0.3, 0.9], [1.0, 0.0]])
    result = evaluate_skin(vertices, pred, ref, skeleton, quarter_turn_of_first_bone())
    assert result["l1"] == pytest.approx(2.5 / 3.0)
    assert result["precision"] == pytest.approx(0.5)
    assert result["recall"] == pytest.approx(2.0 / 3.0)
    assert result["deform_mean"] == pytest.approx(0.75 * math.sqrt(2.0 / 17.0))
    assert result["deform_max"] == pytest.approx(2.0 * math.sqrt(2.0 / 17.0))
    assert result["unweighted"] == 1


def test_evaluate_skin_unweighted_vertex_on_a_chain():
    # Bone b (head (0,0,1), child of a) turns 90 degrees about x. The
    # reference moves vertex (0.2, 0, 1.5) with b to (0.2, -0.5, 1.0); the
    # prediction leaves it unweighted, so it stays: 0.5 sqrt(2) apart.
    # Size: bounding-box diagonal |(0.2, 0, 1)|. Mean over the three vertices.
    vertices = np.array([[0.0, 0.0, 0.5], [0.0, 0.0, 1.5], [0.2, 0.0, 1.5]])
    skeleton = Skeleton([[0, 0, 0], [0, 0, 1]], [-1, 0], ("a", "b"), [[0, 0, 1], [0, 0, 2]])
    reference = Weights(np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 1.0]]), ("a", "b"))
    predicted = Weights(np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]), ("a", "b"))
    poses = np.broadcast_to(np.eye(3), (1, 2, 3, 3)).copy()
    poses[0, 1] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
    scores = evaluate_skin(vertices, predicted, reference, skeleton, poses)
    size = math.hypot(0.2, 1.0)
    assert scores["unweighted"] == 1
    assert scores["deform_max"] == pytest.approx(0.5 * math.sqrt(2) / size)
    assert scores["deform_mean"] == pytest.approx(0.5 * math.sqrt(2) / size / 3)
    assert scores["l1"] == pytest.approx(1.0 / 3)
    assert scores["precision"] == 1.0 and scores["recall"] == pytest.approx(2.0 / 3)


def test_evaluate_transfer_with_and_without_reference():
    # Edge (0,0,0)-(1,0,0); vertex 1 half on the turning bone goes to
    # (0.5,0.5,0): length sqrt(0.5), stretch 1 - sqrt(0.5). Against the
    # reference (vertex 1 fully still, staying at (1,0,0)) it is
    # sqrt(0.5^2 + 0.5^2) = sqrt(0.5) away; size 1: mean sqrt(0.5)/2.
    skeleton = two_root_skeleton()
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    pred = np.array([[1.0, 0.0], [0.5, 0.5]])
    ref = np.array([[1.0, 0.0], [0.0, 1.0]])
    poses = quarter_turn_of_first_bone()
    without = evaluate_transfer(vertices, [[0, 1]], pred, skeleton, poses=poses)
    assert set(without) == {"stretch_p99", "stretch_max"}
    assert without["stretch_max"] == pytest.approx(1.0 - np.sqrt(0.5))
    with_reference = evaluate_transfer(vertices, [[0, 1]], pred, skeleton, weights_ref=ref, poses=poses)
    assert with_reference["deform_max"] == pytest.approx(np.sqrt(0.5))
    assert with_reference["deform_mean"] == pytest.approx(np.sqrt(0.5) / 2.0)


def test_evaluate_transfer_default_poses_are_seeded():
    skeleton = two_root_skeleton()
    rng = np.random.default_rng(5)
    vertices = rng.normal(size=(20, 3))
    weights = rng.random((20, 2))
    weights /= weights.sum(axis=1, keepdims=True)
    edges = np.array([[k, k + 1] for k in range(19)])
    first = evaluate_transfer(vertices, edges, weights, skeleton)
    again = evaluate_transfer(vertices, edges, weights, skeleton, poses=random_poses(skeleton, seed=0))
    assert first == again
    assert first["stretch_max"] > 0.0
